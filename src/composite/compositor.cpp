// composite/compositor.cpp — tile binning and per-tile front-to-back compositing (see compositor.h).
#include "composite/compositor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>

#include "composite/opacity.h"
#include "footprint/kernel.h"

namespace vdbsplat {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Sort key: slab (relative to the window), then points before splats, then depth.
uint64_t sortKey(const Primitive& p, int64_t slabBase) {
    const uint64_t slab = uint64_t(std::clamp<int64_t>(p.slab - slabBase, 0, (int64_t(1) << 27) - 1));
    const uint64_t kind = p.kind == PrimitiveKind::Point ? 0 : 1;
    const uint64_t depth = std::bit_cast<uint32_t>(std::max(p.depth, 0.f));  // monotone for floats ≥ 0
    return slab << 33 | kind << 32 | depth;
}
}  // namespace

/// Optical depth and σ-weighted colour of the points of the current slab, per tile pixel.
struct TileCompositor::SlabBuffer {
    std::array<float, kTileSize * kTileSize> tau{};
    std::array<glm::vec3, kTileSize * kTileSize> emission{};
    bool dirty = false;
};

TileCompositor::TileCompositor(int width, int height, const Tables& tables, const ExactContext& exact)
    : width_(width), height_(height), tilesX_((width + kTileSize - 1) / kTileSize),
      tilesY_((height + kTileSize - 1) / kTileSize), tables_(tables), exact_(exact),
      color_(size_t(width) * height, glm::vec3(0.f)), transmittance_(size_t(width) * height, 1.f),
      liveCount_(size_t(tilesX_) * tilesY_), bins_(size_t(tilesX_) * tilesY_) {
    for (int ty = 0; ty < tilesY_; ++ty)
        for (int tx = 0; tx < tilesX_; ++tx)
            liveCount_[size_t(ty) * tilesX_ + tx] = (std::min(width_, (tx + 1) * kTileSize) - tx * kTileSize) *
                                                    (std::min(height_, (ty + 1) * kTileSize) - ty * kTileSize);
}

bool TileCompositor::hidden(int x0, int y0, int x1, int y1) const {
    for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty)
        for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx)
            if (liveCount_[size_t(ty) * tilesX_ + tx] > 0) return false;
    return true;
}

Image TileCompositor::image() const {
    Image image(width_, height_);
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = glm::vec4(color_[i], 1.f - transmittance_[i]);
    return image;
}

SkippedPrimitives TileCompositor::composite(const std::vector<Primitive>& prims, double& binSeconds, double& compositeSeconds) {
    const auto t0 = Clock::now();
    int64_t slabBase = std::numeric_limits<int64_t>::max();
    for (const Primitive& p : prims)
        if (p.kind != PrimitiveKind::Culled) slabBase = std::min(slabBase, p.slab);
    SkippedPrimitives skipped;
    for (auto& bin : bins_) bin.clear();
    for (uint32_t i = 0; i < prims.size(); ++i) {
        const Primitive& p = prims[i];
        if (p.kind == PrimitiveKind::Culled || p.range.empty()) continue;
        const uint64_t key = sortKey(p, slabBase);
        bool any = false;
        for (int ty = p.range.y0 / kTileSize; ty <= p.range.y1 / kTileSize; ++ty)
            for (int tx = p.range.x0 / kTileSize; tx <= p.range.x1 / kTileSize; ++tx) {
                const size_t tile = size_t(ty) * tilesX_ + tx;
                if (liveCount_[tile] == 0) continue;
                bins_[tile].push_back({key, i});
                any = true;
            }
        if (!any) ++(p.kind == PrimitiveKind::Point ? skipped.points : skipped.splats);
    }
    binSeconds += since(t0);
    const auto t1 = Clock::now();
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX_ * tilesY_, 1), [&](const tbb::blocked_range<int>& r) {
        for (int tile = r.begin(); tile < r.end(); ++tile)
            if (!bins_[tile].empty()) compositeTile(tile, bins_[tile], prims);
    });
    compositeSeconds += since(t1);
    return skipped;
}

[[gnu::always_inline]] inline void TileCompositor::over(size_t pixel, float tau, const glm::vec3& color) {
    // α = 1 − exp(−τ);  C += T·α·c;  T *= 1 − α   (DESIGN §4)
    const float alpha = opacityFromOpticalDepth(tau);
    float& T = transmittance_[pixel];
    color_[pixel] += T * alpha * color;
    T *= 1.f - alpha;
}

void TileCompositor::compositeTile(int tile, std::vector<Entry>& entries, const std::vector<Primitive>& prims) {
    std::sort(entries.begin(), entries.end());
    const int tx0 = (tile % tilesX_) * kTileSize, ty0 = (tile / tilesX_) * kTileSize;
    const int tx1 = std::min(width_, tx0 + kTileSize) - 1, ty1 = std::min(height_, ty0 + kTileSize) - 1;
    SlabBuffer slab;
    int64_t slabOf = std::numeric_limits<int64_t>::min();
    const auto flush = [&] {
        if (!slab.dirty) return;
        for (int y = ty0; y <= ty1; ++y)
            for (int x = tx0; x <= tx1; ++x) {
                const int local = (y - ty0) * kTileSize + (x - tx0);
                const float tau = slab.tau[local];
                if (tau > 0.f) over(size_t(y) * width_ + x, tau, slab.emission[local] / tau);
                slab.tau[local] = 0.f;
                slab.emission[local] = glm::vec3(0.f);
            }
        slab.dirty = false;
    };
    const auto countLive = [&] {
        int live = 0;
        for (int y = ty0; y <= ty1; ++y)
            for (int x = tx0; x <= tx1; ++x) live += transmittance_[size_t(y) * width_ + x] >= kTransmittanceEpsilon;
        return live;
    };
    for (size_t e = 0; e < entries.size(); ++e) {
        const Primitive& p = prims[entries[e].index];
        const bool isPoint = p.kind == PrimitiveKind::Point;
        if (p.slab != slabOf || !isPoint) {
            flush();
            slabOf = p.slab;
        }
        // Tile-level early termination, checked every 32 primitives.
        if ((e & 31) == 31 && !slab.dirty && countLive() == 0) break;
        switch (p.kind) {
            case PrimitiveKind::Point: drawPoint(p, tx0, ty0, tx1, ty1, slab); break;
            case PrimitiveKind::Splat: drawSplat(p, tx0, ty0, tx1, ty1); break;
            case PrimitiveKind::SplatExact:
            case PrimitiveKind::NearEye: drawExact(p, tx0, ty0, tx1, ty1); break;
            case PrimitiveKind::Culled: break;
        }
    }
    flush();
    liveCount_[tile] = countLive();
}

void TileCompositor::drawPoint(const Primitive& p, int tx0, int ty0, int tx1, int ty1, SlabBuffer& slab) {
    const PointFootprint fp = rasterizePoint(pointFilter_, PixelCoord(p.centre), p.variance);
    const int x0 = std::max(fp.x0, tx0), x1 = std::min(fp.x0 + fp.nx - 1, tx1);
    const int y0 = std::max(fp.y0, ty0), y1 = std::min(fp.y0 + fp.ny - 1, ty1);
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            if (transmittance_[size_t(y) * width_ + x] < kTransmittanceEpsilon) continue;
            const float tau = p.total * fp.at(x - fp.x0, y - fp.y0);
            const int local = (y - ty0) * kTileSize + (x - tx0);
            slab.tau[local] += tau;
            slab.emission[local] += tau * p.color;
        }
    slab.dirty = true;
}

void TileCompositor::drawSplat(const Primitive& p, int tx0, int ty0, int tx1, int ty1) {
    const int x0 = std::max(p.range.x0, tx0), x1 = std::min(p.range.x1, tx1);
    const int y0 = std::max(p.range.y0, ty0), y1 = std::min(p.range.y1, ty1);
    const float qxx = p.conic.x, qxy = p.conic.y, qyy = p.conic.z;
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y) + 0.5f - p.centre.y;
        // The row's chord of the support ellipse, i² < 1:  qxx dx² + 2 qxy dy dx + qyy dy² − 1 < 0.
        // One pixel of slack on each side; the i² test below decides exactly as before.
        const float b = qxy * dy, disc = b * b - qxx * (qyy * dy * dy - 1.f);
        if (!(disc > 0.f)) continue;
        const float root = std::sqrt(disc);
        const float lo = p.centre.x - 0.5f + (-b - root) / qxx, hi = p.centre.x - 0.5f + (-b + root) / qxx;
        const int xa = std::max(x0, int(std::floor(lo))), xb = std::min(x1, int(std::ceil(hi)));
        for (int x = xa; x <= xb; ++x) {
            const size_t pixel = size_t(y) * width_ + x;
            if (transmittance_[pixel] < kTransmittanceEpsilon) continue;
            const float dx = float(x) + 0.5f - p.centre.x;
            const float i2 = qxx * dx * dx + 2.f * qxy * dx * dy + qyy * dy * dy;
            if (!(i2 < 1.f)) continue;
            over(pixel, p.shader.depositAtIndex2(i2), p.color);
        }
    }
}

void TileCompositor::drawExact(const Primitive& p, int tx0, int ty0, int tx1, int ty1) {
    const Camera& camera = *exact_.camera;
    const double h = exact_.voxelSize;
    const SphereProjection sphere = projectSphere(camera, ViewPoint(p.viewPos), Kernel::kRadius * h);
    const bool widened = p.kind == PrimitiveKind::SplatExact && sphere.isEllipse();
    ScreenKernel kernel;
    if (widened) kernel = makeScreenKernel(sphere);
    const int x0 = std::max(p.range.x0, tx0), x1 = std::min(p.range.x1, tx1);
    const int y0 = std::max(p.range.y0, ty0), y1 = std::min(p.range.y1, ty1);
    const double sigmaWorld = p.sigma / h;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const size_t pixel = size_t(y) * width_ + x;
            if (transmittance_[pixel] < kTransmittanceEpsilon) continue;
            const PixelCoord q(x + 0.5, y + 0.5);
            const double tau = widened ? splatDepositExact(kernel, sphere, sigmaWorld, h, q)
                                       : p.sigma * halfRayFootprint(sphere, q);
            if (tau > 0.0) over(pixel, float(tau), p.color);
        }
}

}  // namespace vdbsplat
