// volume/stream.cpp — depth-ordered block streaming (see stream.h, DESIGN §5).
#include "volume/stream.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "footprint/kernel.h"
#include "util/error.h"

namespace vdbsplat {

namespace {
constexpr int kBlockDim = 8;  // OpenVDB leaf side; active tiles are split into blocks of this side
constexpr uint64_t kMaxActiveVoxels = uint64_t(1) << 32;

template <typename T>
void appendRange(std::vector<T>& dst, const std::vector<T>& src, size_t begin, size_t end) {
    dst.insert(dst.end(), src.begin() + begin, src.begin() + end);
}
}  // namespace

void VoxelBatch::clear() {
    viewPos.clear();
    distance.clear();
    sigma.clear();
    color.clear();
}

VoxelStream::VoxelStream(const Volume& volume, const Camera& camera, const ClassificationTable& table,
                         const StreamOptions& options)
    : volume_(volume), camera_(camera), table_(table), options_(options),
      slabLength_(options.slabThickness * volume.voxelSize), slabsPerWindow_(std::max(1, options.slabsPerWindow)) {
    if (volume.activeVoxels > kMaxActiveVoxels)
        throw Error(volume.file + ": grid '" + volume.name + "' has " + std::to_string(volume.activeVoxels) +
                    " active voxels, more than the 2^32 vdbsplat streams");
    collectBlocks();
}

void VoxelStream::collectBlocks() {
    const auto& tree = volume_.grid->tree();
    std::vector<Block> all;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        if (leaf->onVoxelCount() == 0) continue;
        all.push_back({leaf->origin(), kBlockDim, &*leaf, 0.f, 0.f, 0.f, uint32_t(leaf->onVoxelCount())});
    }
    // Active tiles (values above leaf level): split into virtual 8³ blocks.
    auto it = tree.cbeginValueOn();
    it.setMaxDepth(it.getLeafDepth() - 1);
    for (; it; ++it) {
        if (!it.isTileValue()) continue;
        const openvdb::CoordBBox box = it.getBoundingBox();
        for (int x = box.min().x(); x <= box.max().x(); x += kBlockDim)
            for (int y = box.min().y(); y <= box.max().y(); y += kBlockDim)
                for (int z = box.min().z(); z <= box.max().z(); z += kBlockDim)
                    all.push_back({openvdb::Coord(x, y, z), kBlockDim, nullptr, *it, 0.f, 0.f,
                                   uint32_t(kBlockDim * kBlockDim * kBlockDim)});
    }
    // Distance bounds of voxel centres: the block's bounding sphere around its centre.
    const double h = volume_.voxelSize;
    const double halfDiagonal = 0.5 * (kBlockDim - 1) * std::sqrt(3.0) * h;
    for (Block& b : all) {
        const glm::dvec3 centreIdx = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + 0.5 * (b.dim - 1);
        const glm::dvec3 centre(volume_.indexToWorld * glm::dvec4(centreIdx, 1.0));
        const double dist = glm::length(centre - camera_.eye());
        b.dMin = float(std::max(0.0, dist - halfDiagonal));
        b.dMax = float(dist + halfDiagonal);
    }
    blocks_.clear();
    for (const Block& b : all) {
        if (visible(b)) blocks_.push_back(b);
        else culled_ += b.voxels;
    }
    // Front to back by nearest distance; ties broken by position so the order is total.
    std::sort(blocks_.begin(), blocks_.end(), [](const Block& a, const Block& b) {
        if (a.dMin != b.dMin) return a.dMin < b.dMin;
        return a.origin < b.origin;
    });
}

bool VoxelStream::visible(const Block& b) const {
    const double h = volume_.voxelSize;
    const glm::dvec3 centreIdx = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + 0.5 * (b.dim - 1);
    const glm::dvec3 c = camera_.toView(glm::dvec3(volume_.indexToWorld * glm::dvec4(centreIdx, 1.0)));
    const double radius = (0.5 * (b.dim - 1) * std::sqrt(3.0) + Kernel::kRadius) * h;
    if (c.z < -radius) return false;  // entirely behind the eye
    // Side planes of the frustum widened by the screen margin: x = ±z·tx, y = ±z·ty.
    const double tx = (0.5 * camera_.width() + options_.screenMargin) / camera_.focal();
    const double ty = (0.5 * camera_.height() + options_.screenMargin) / camera_.focal();
    const double nx = 1.0 / std::sqrt(1.0 + tx * tx), ny = 1.0 / std::sqrt(1.0 + ty * ty);
    if ((std::abs(c.x) - tx * c.z) * nx > radius) return false;
    if ((std::abs(c.y) - ty * c.z) * ny > radius) return false;
    return true;
}

void VoxelStream::screenRect(const Block& b, int& x0, int& y0, int& x1, int& y1) const {
    // Project the corners of the block's box widened by the kernel radius; the margin
    // covers the prefilter. Any corner at or behind the eye plane: the whole screen.
    const double r = Kernel::kRadius + 0.5;
    double lox = 1e300, loy = 1e300, hix = -1e300, hiy = -1e300;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 idx(b.origin.x() + (corner & 1 ? b.dim - 1 + r : -r),
                             b.origin.y() + (corner & 2 ? b.dim - 1 + r : -r),
                             b.origin.z() + (corner & 4 ? b.dim - 1 + r : -r));
        const glm::dvec3 v = camera_.toView(glm::dvec3(volume_.indexToWorld * glm::dvec4(idx, 1.0)));
        if (v.z <= 1e-6) {
            x0 = y0 = 0;
            x1 = camera_.width() - 1;
            y1 = camera_.height() - 1;
            return;
        }
        const PixelCoord p = camera_.project(v);
        lox = std::min(lox, p.x), hix = std::max(hix, p.x);
        loy = std::min(loy, p.y), hiy = std::max(hiy, p.y);
    }
    const double m = options_.screenMargin;
    x0 = int(std::clamp(std::floor(lox - m), 0.0, double(camera_.width() - 1)));
    x1 = int(std::clamp(std::ceil(hix + m), 0.0, double(camera_.width() - 1)));
    y0 = int(std::clamp(std::floor(loy - m), 0.0, double(camera_.height() - 1)));
    y1 = int(std::clamp(std::ceil(hiy + m), 0.0, double(camera_.height() - 1)));
}

void VoxelStream::extract(const Block& b, VoxelBatch& out) const {
    const glm::dmat4 indexToView = [&] {
        // view = R·(world − eye) with rows right, up, forward.
        glm::dmat4 worldToView(1.0);
        const glm::dvec3 r = camera_.right(), u = camera_.up(), f = camera_.forward();
        for (int c = 0; c < 3; ++c) {
            worldToView[c][0] = r[c];
            worldToView[c][1] = u[c];
            worldToView[c][2] = f[c];
        }
        worldToView[3] = glm::dvec4(-glm::dot(r, camera_.eye()), -glm::dot(u, camera_.eye()),
                                    -glm::dot(f, camera_.eye()), 1.0);
        return worldToView * volume_.indexToWorld;
    }();
    const auto emit = [&](const openvdb::Coord& ijk, float value) {
        const Classified cls = table_(value);
        if (!(cls.sigma > 0.f)) return;
        const glm::dvec3 v(indexToView * glm::dvec4(ijk.x(), ijk.y(), ijk.z(), 1.0));
        out.viewPos.emplace_back(v);
        out.distance.push_back(float(glm::length(v)));
        out.sigma.push_back(cls.sigma);
        out.color.push_back(cls.color);
    };
    if (b.leaf) {
        for (auto it = b.leaf->cbeginValueOn(); it; ++it) emit(it.getCoord(), *it);
    } else {
        openvdb::Coord ijk;
        for (ijk[0] = b.origin.x(); ijk[0] < b.origin.x() + b.dim; ++ijk[0])
            for (ijk[1] = b.origin.y(); ijk[1] < b.origin.y() + b.dim; ++ijk[1])
                for (ijk[2] = b.origin.z(); ijk[2] < b.origin.z() + b.dim; ++ijk[2]) emit(ijk, b.tileValue);
    }
}

void VoxelStream::adaptWindow(size_t released) {
    const int widest = std::max(1, options_.slabsPerWindow);
    if (released > options_.maxWindowVoxels && slabsPerWindow_ > 1) slabsPerWindow_ /= 2;
    else if (released < options_.maxWindowVoxels / 4 && slabsPerWindow_ < widest)
        slabsPerWindow_ = std::min(widest, 2 * slabsPerWindow_);
}

bool VoxelStream::next(VoxelBatch& batch, const std::function<bool(int, int, int, int)>& hidden) {
    batch.clear();
    while (true) {
        if (pending_.size() == 0) {
            if (nextBlock_ >= blocks_.size()) return false;
            // Skip empty depth: jump to the next block's front.
            nextSlab_ = std::max<int64_t>(nextSlab_, int64_t(std::floor(blocks_[nextBlock_].dMin / slabLength_)));
        }
        // The window: at least slabsPerWindow slabs, grown while it would hold too few voxels.
        int64_t slabEnd = nextSlab_ + slabsPerWindow_;
        size_t first = nextBlock_;
        size_t estimate = pending_.size();
        while (nextBlock_ < blocks_.size() && blocks_[nextBlock_].dMin < slabEnd * slabLength_) {
            estimate += blocks_[nextBlock_].voxels;
            ++nextBlock_;
            if (nextBlock_ < blocks_.size() && estimate < options_.minWindowVoxels &&
                blocks_[nextBlock_].dMin >= slabEnd * slabLength_)
                slabEnd = int64_t(std::floor(blocks_[nextBlock_].dMin / slabLength_)) + slabsPerWindow_;
        }
        // Activate the blocks whose front the window reached: extract them in parallel, in order.
        std::vector<VoxelBatch> extracted(nextBlock_ - first);
        std::vector<char> skipped(nextBlock_ - first, 0);
        tbb::parallel_for(tbb::blocked_range<size_t>(first, nextBlock_, 16), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const Block& b = blocks_[i];
                if (hidden) {
                    int x0, y0, x1, y1;
                    screenRect(b, x0, y0, x1, y1);
                    if (hidden(x0, y0, x1, y1)) {
                        skipped[i - first] = 1;
                        continue;
                    }
                }
                extract(b, extracted[i - first]);
            }
        });
        for (size_t i = first; i < nextBlock_; ++i) {
            const VoxelBatch& e = extracted[i - first];
            if (skipped[i - first]) culled_ += blocks_[i].voxels;
            appendRange(pending_.viewPos, e.viewPos, 0, e.size());
            appendRange(pending_.distance, e.distance, 0, e.size());
            appendRange(pending_.sigma, e.sigma, 0, e.size());
            appendRange(pending_.color, e.color, 0, e.size());
        }
        // Release the pending voxels inside the window; keep the rest in order.
        const float limit = float(slabEnd * slabLength_);
        VoxelBatch keep;
        for (size_t i = 0; i < pending_.size(); ++i) {
            VoxelBatch& dst = pending_.distance[i] < limit ? batch : keep;
            dst.viewPos.push_back(pending_.viewPos[i]);
            dst.distance.push_back(pending_.distance[i]);
            dst.sigma.push_back(pending_.sigma[i]);
            dst.color.push_back(pending_.color[i]);
        }
        pending_ = std::move(keep);
        batch.slabBegin = nextSlab_;
        batch.slabEnd = slabEnd;
        nextSlab_ = slabEnd;
        adaptWindow(batch.size());
        if (batch.size() > 0) {
            ++windows_;
            largest_ = std::max(largest_, batch.size());
            return true;
        }
    }
}

}  // namespace vdbsplat
