// composite/compositor.cpp — tile binning and per-tile front-to-back compositing (see compositor.h).
#include "composite/compositor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>

#include "composite/opacity.h"
#include "composite/point_raster.h"
#include "composite/splat_raster.h"
#include "composite/tile_sort.h"
#include "footprint/kernel.h"

namespace vdbsplat {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The order of a window: slab, then points before splats, then depth (then the primitive's
/// index, which the stable sort keeps). Packed into as few bits as the window's range needs:
///     key = ((slab − slabBase) · 2 + kind) · 2^depthBits + ((depth bits − depthBase) >> depthShift)
/// with the depth's float bits (monotone for floats ≥ 0), so the radix sort makes few passes.
/// The key sits above the index in a 64-bit entry; depthShift drops the depth's lowest bits
/// only where key and index would not fit (a window spanning more than ~2^(64 − index bits −
/// slab bits) float steps of depth: never in the test scenes; ties then go by index).
struct KeyLayout {
    uint32_t orderBase = 0;  ///< the smallest ProjectedWindow::order (relative slab·2 + kind)
    uint32_t depthBase = 0;
    int depthBits = 0;
    int depthShift = 0;
    int bits = 0;  ///< the key's width

    static uint32_t depthOf(float depth) { return std::bit_cast<uint32_t>(std::max(depth, 0.f)); }
    uint64_t key(uint32_t order, float depth) const {
        return (uint64_t(order - orderBase) << depthBits) | ((depthOf(depth) - depthBase) >> depthShift);
    }
};

/// The fixed chunks a window's n entries are cut into for the binning's parallel passes (key
/// ranges and counts, fill): by n alone, never by the thread count, so nothing depends on it. 4 096
/// entries a chunk (up to 64 chunks): 16 384 made a typical 50k-entry window 3 chunks for 2
/// threads, at most 1.5× (session 11).
struct Chunks {
    size_t n, count, per;
    explicit Chunks(size_t entries)
        : n(entries), count(std::clamp<size_t>(entries / 4096, 1, 64)), per((entries + count - 1) / count) {}
    size_t begin(size_t c) const { return c * per; }
    size_t end(size_t c) const { return std::min(n, (c + 1) * per); }
};

/// Per chunk of a window: drawable primitives and the range of their slabs and depth bits.
struct ChunkRange {
    size_t count = 0;
    uint32_t orderLo = std::numeric_limits<uint32_t>::max(), orderHi = 0;
    uint32_t depthLo = std::numeric_limits<uint32_t>::max(), depthHi = 0;
};

}  // namespace

/// Optical depth and σ-weighted colour of the points of the current slab, per tile pixel
/// (structure of arrays, 64-byte aligned: the point loop loads whole rows; point_raster.h).
///
/// The four planes lie kPlane floats apart, 64 bytes more than a tile's 4 KiB (session 36): at
/// 4 KiB apart a pixel's four sums, and the same pixel of every slot of a SlabRing (16 448 bytes
/// apart), fell into the same or neighbouring sets of the 8-way, 64-set L1 data cache, and a
/// splat of the slab order touches 9 slots × 4 planes × its rows there; the padded planes made the
/// shaded framed Engine 1.6× and close 1.9× faster (docs/performance.md, session 36).
struct TileCompositor::SlabBuffer {
    static constexpr size_t kPlane = kTilePixels + 16;
    alignas(64) std::array<float, 4 * kPlane> sums{};
    float* tau() { return sums.data(); }
    float* er() { return sums.data() + kPlane; }
    float* eg() { return sums.data() + 2 * kPlane; }
    float* eb() { return sums.data() + 3 * kPlane; }
    bool dirty = false;
    /// The image pixels the kernel order's points have deposited into since the slab was last
    /// composited (x1 < x0: not tracked, the whole tile): compositing reads only those (a far
    /// view's slab holds a few points of a tile's 1 024 pixels).
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    void touch(int ax0, int ay0, int ax1, int ay1) {
        if (x1 < x0) {
            x0 = ax0, y0 = ay0, x1 = ax1, y1 = ay1;
            return;
        }
        x0 = std::min(x0, ax0), y0 = std::min(y0, ay0), x1 = std::max(x1, ax1), y1 = std::max(y1, ay1);
    }
    /// The tile pixels to composite (tile-local: the tracked pixels inside the tile @p px0 … @p px1,
    /// or all of its image pixels), and the tracking cleared for the next slab.
    TileRect take(int px0, int py0, int px1, int py1) {
        const bool tracked = x1 >= x0;
        const TileRect r{(tracked ? std::max(px0, x0) : px0) - px0, (tracked ? std::max(py0, y0) : py0) - py0,
                         (tracked ? std::min(px1, x1) : px1) - px0, (tracked ? std::min(py1, y1) : py1) - py0};
        x0 = 0, y0 = 0, x1 = -1, y1 = -1;
        return r;
    }
};

/// --compositing slabs: one tile's open slabs [first, last] (last < first: none), slab s in
/// slot s mod (2K + 1). Slabs before `first` are composited; a primitive of slab s deposits into
/// s − K … s + K, so before it is drawn every slab before s − K is closed (the tile's list is in
/// slab order, and every window's slabs follow the previous window's).
struct TileCompositor::SlabRing {
    int64_t first = std::numeric_limits<int64_t>::min() + 1;
    int64_t last = std::numeric_limits<int64_t>::min();
    std::vector<SlabBuffer> slot;
    explicit SlabRing(int reach) : slot(size_t(2 * reach + 1)) {}
    bool open() const { return last >= first; }
    size_t slotOf(int64_t slab) const {  // slabs before the eye (first < 0 near it) hold nothing, but are walked
        const int64_t n = int64_t(slot.size()), r = slab % n;
        return size_t(r < 0 ? r + n : r);
    }
    SlabBuffer& at(int64_t slab) { return slot[slotOf(slab)]; }
    /// Sets @p t to the slabs a primitive of slab @p slab with @p profile deposits into (those of
    /// non-zero fraction), marked dirty and open. @p t is the caller's, reused from primitive to
    /// primitive: its entries past `count` are left as they were (zeroing the 336-byte record for
    /// every primitive was a tenth of the tile loop's own time). One division per primitive: slab
    /// s − K + j lies in slot (slotOf(s − K) + j) mod (2K + 1), j ≤ 2K.
    /// @p grey: without the green and blue sums (ColorChannels::Grey).
    void targets(const SlabProfile& profile, int64_t slab, int reach, bool grey, SlabTargets& t) {
        t.count = 0;
        const size_t slots = slot.size();
        size_t k = slotOf(slab - reach);
        for (int j = 0; j <= 2 * reach; ++j, k = k + 1 == slots ? 0 : k + 1) {
            const float f = profile.fraction[size_t(j)];
            if (!(f > 0.f)) continue;
            // Never before the first open slab (only a primitive out of slab order could ask for it).
            const int64_t to = std::max(slab - reach + j, first);
            SlabBuffer& b = to == slab - reach + j ? slot[k] : at(to);
            b.dirty = true;
            last = open() ? std::max(last, to) : to;
            const size_t n = size_t(t.count++);
            t.tau[n] = b.tau(), t.er[n] = b.er();
            t.eg[n] = grey ? nullptr : b.eg(), t.eb[n] = grey ? nullptr : b.eb();
            t.fraction[n] = f;
        }
    }
};

TileCompositor::TileCompositor(int width, int height, const Tables& tables, const ExactContext& exact, SlabCompositing slabs,
                               CompositorBuffers* buffers, ColorChannels channels, float cutoff)
    : width_(width), height_(height), tilesX_((width + kTileSize - 1) / kTileSize),
      tilesY_((height + kTileSize - 1) / kTileSize), tables_(tables), exact_(exact), slabs_(slabs), epsilon_(cutoff),
      grey_(channels == ColorChannels::Grey && exact.vector),
      own_(buffers ? nullptr : std::make_unique<CompositorBuffers>()), kept_(buffers ? *buffers : *own_),
      color_(kept_.color), transmittance_(kept_.transmittance), liveCount_(size_t(tilesX_) * tilesY_),
      binStart_(kept_.binStart), binEntries_(kept_.binEntries), binScratch_(kept_.binScratch), binCounts_(kept_.binCounts) {
    const size_t pixels = size_t(width) * height;
    growDiscarding(color_, pixels), growDiscarding(transmittance_, pixels);  // filled here, in parallel
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 16384), [&](const tbb::blocked_range<size_t>& r) {
        std::fill(color_.begin() + ptrdiff_t(r.begin()), color_.begin() + ptrdiff_t(r.end()), glm::vec3(0.f));
        std::fill(transmittance_.begin() + ptrdiff_t(r.begin()), transmittance_.begin() + ptrdiff_t(r.end()), 1.f);
    });
    for (int ty = 0; ty < tilesY_; ++ty)
        for (int tx = 0; tx < tilesX_; ++tx)
            liveCount_[size_t(ty) * tilesX_ + tx] = (std::min(width_, (tx + 1) * kTileSize) - tx * kTileSize) *
                                                    (std::min(height_, (ty + 1) * kTileSize) - ty * kTileSize);
    liveRows_.resize(size_t(height_) * size_t(tilesX_));
    for (int y = 0; y < height_; ++y)
        for (int tx = 0; tx < tilesX_; ++tx) {
            const int columns = std::min(width_, (tx + 1) * kTileSize) - tx * kTileSize;  // 1 … 32
            liveRows_[size_t(y) * tilesX_ + tx] = ~uint32_t(0) >> (kTileSize - columns);
        }
    slabs_.reach = std::clamp(slabs_.reach, 0, kMaxSlabReach);
    if (slabs_.on) rings_.resize(size_t(tilesX_) * tilesY_);
}

TileCompositor::~TileCompositor() = default;

Image TileCompositor::image() const {
    Image image(width_, height_);
    adviseRowsWritten(image, 0, height_, width_);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, image.pixels.size(), 16384), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) image.pixels[i] = glm::vec4(color_[i], 1.f - transmittance_[i]);
    });
    return image;
}

SkippedPrimitives TileCompositor::composite(std::span<const Primitive> prims, double& binSeconds, double& compositeSeconds) {
    int64_t base = std::numeric_limits<int64_t>::max();
    for (const Primitive& p : prims) base = std::min(base, p.slab);
    packed_.slabBase = prims.empty() ? 0 : base;
    int64_t end = packed_.slabBase;
    for (const Primitive& p : prims) end = std::max(end, p.slab + 1);
    packed_.slabEnd = end;
    packed_.profiles = slabs_.on;
    packed_.resize(prims.size());
    for (size_t i = 0; i < prims.size(); ++i) packed_.set(i, prims[i]);
    return composite(packed_, binSeconds, compositeSeconds);
}

SkippedPrimitives TileCompositor::composite(const ProjectedWindow& window, double& binSeconds, double& compositeSeconds) {
    const auto t0 = Clock::now();
    window_ = &window;
    const SkippedPrimitives skipped = binWindow(window);
    binSeconds += since(t0);
    const auto t1 = Clock::now();
    // Slabs: every slab before closeBefore is past (the next window's primitives, of slabs ≥
    // slabEnd, reach back to slabEnd − K); tiles with open slabs and no primitive close them too.
    const int64_t closeBefore = window.slabEnd - slabs_.reach;
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX_ * tilesY_, 1), [&](const tbb::blocked_range<int>& r) {
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const size_t first = binStart_[size_t(tile)], count = binStart_[size_t(tile) + 1] - first;
            const Entry* sorted = count == 0 ? nullptr
                                             : sortTileEntries(binEntries_.data() + first, binScratch_.data() + first,
                                                               count, indexBits_, keyBits_);
            const std::span<const Entry> bin(sorted, count);
            if (slabs_.on) {
                const SlabRing* ring = rings_[size_t(tile)].get();
                if (!bin.empty() || (ring && ring->open() && ring->first < closeBefore)) compositeTileSlabs(tile, bin, closeBefore);
            } else if (!bin.empty()) {
                compositeTile(tile, bin);
            }
        }
    });
    compositeSeconds += since(t1);
    window_ = nullptr;
    return skipped;
}

/// Bins the window's drawable primitives into per-tile lists (CSR: binStart_, binEntries_) of sort
/// entries, key << indexBits_ | index (KeyLayout), each list in index order; the tiles sort their
/// own lists (sortTileEntries) just before compositing them. Parallel over fixed chunks of the
/// window in index order, reading 16 bytes a primitive (order, depth, tiles): per chunk, the key range and
/// the count per tile (skipping tiles already opaque); then the layout, the offsets tile by tile
/// and chunk by chunk, and the fill. The lists, and each tile's sorted order (the total (key,
/// index) order restricted to the tile), depend neither on the chunking nor on the thread count.
/// Until session 15 the whole window was radix-sorted once and binned in that order: three or
/// four passes over the window's entries in memory, and every record read in sorted order, a
/// random line each (docs/performance.md, session 15).
SkippedPrimitives TileCompositor::binWindow(const ProjectedWindow& window) {
    const size_t tiles = size_t(tilesX_) * tilesY_, n = window.size;
    const Chunks chunks(n);
    const uint32_t* orderOf = window.order.data();
    const float* depthOf = window.depth.data();
    std::vector<uint32_t>& counts = binCounts_;  // reused: fresh pages cost a fault each on every window
    counts.assign(chunks.count * tiles, 0);
    std::vector<ChunkRange> range(chunks.count);
    std::vector<SkippedPrimitives> skippedIn(chunks.count);
    const uint64_t* tilesOf = window.tiles.data();
    const int* live = liveCount_.data();
    const size_t tilesX = size_t(tilesX_);
    // Everything the loops read through locals: a store through a count or an entry could alias a
    // member or a captured reference, and the compiler reloaded them every primitive.
    const auto forTiles = [live, tilesX](uint64_t rect, auto&& fn) {  // rect: tileRect of the primitive's range
        const size_t tx0 = rect & 0xffff, ty0 = rect >> 16 & 0xffff, tx1 = rect >> 32 & 0xffff, ty1 = rect >> 48;
        for (size_t ty = ty0; ty <= ty1; ++ty)
            for (size_t tile = ty * tilesX + tx0, last = ty * tilesX + tx1; tile <= last; ++tile)
                if (live[tile] > 0) fn(tile);
    };
    // Per chunk: the drawable primitives' key range (all of them, as the layout always took) and
    // the tiles each counts in; a primitive with no live tile is skipped.
    tbb::parallel_for(size_t(0), chunks.count, [&](size_t c) {
        uint32_t* const count = counts.data() + c * tiles;
        ChunkRange r;
        SkippedPrimitives skipped;
        for (size_t i = chunks.begin(c), end = chunks.end(c); i < end; ++i) {
            const uint32_t o = orderOf[i];
            if (o == ProjectedWindow::kNotDrawn) continue;
            ++r.count;
            const uint32_t d = KeyLayout::depthOf(depthOf[i]);
            r.orderLo = std::min(r.orderLo, o), r.orderHi = std::max(r.orderHi, o);
            r.depthLo = std::min(r.depthLo, d), r.depthHi = std::max(r.depthHi, d);
            bool any = false;
            forTiles(tilesOf[i], [&](size_t tile) { ++count[tile], any = true; });
            if (!any) {
                const PrimitiveRecord& p = window.records[i];
                ++(p.kind == PrimitiveKind::Point ? skipped.points : skipped.splats);
                if (p.kind == PrimitiveKind::SplatExactIndex) ++skipped.exactIndexSplats;
                skipped.voxels += window.members[i];
            }
        }
        range[c] = r, skippedIn[c] = skipped;
    });
    ChunkRange all;
    for (const ChunkRange& r : range) {
        all.count += r.count;
        all.orderLo = std::min(all.orderLo, r.orderLo), all.orderHi = std::max(all.orderHi, r.orderHi);
        all.depthLo = std::min(all.depthLo, r.depthLo), all.depthHi = std::max(all.depthHi, r.depthHi);
    }
    KeyLayout layout;
    indexBits_ = std::max(1, int(std::bit_width(std::max<size_t>(n, 1) - 1)));
    if (all.count > 0) {
        // order = relative slab·2 + kind: the slab's bits and the kind's one.
        layout.orderBase = all.orderLo & ~1u, layout.depthBase = all.depthLo;
        const int orderBits = int(std::bit_width(all.orderHi - layout.orderBase));
        const int depthBits = int(std::bit_width(all.depthHi - all.depthLo));
        layout.depthShift = std::max(0, orderBits + depthBits - (64 - indexBits_));
        layout.depthBits = depthBits - layout.depthShift;
        layout.bits = orderBits + layout.depthBits;
    }
    keyBits_ = layout.bits;
    // Offsets: tile by tile, chunk by chunk; counts become each chunk's write cursor.
    binStart_.assign(tiles + 1, 0);
    size_t total = 0;
    for (size_t tile = 0; tile < tiles; ++tile) {
        binStart_[tile] = total;
        for (size_t c = 0; c < chunks.count; ++c) {
            const uint32_t k = counts[c * tiles + tile];
            counts[c * tiles + tile] = uint32_t(total);
            total += k;
        }
    }
    binStart_[tiles] = total;
    growDiscarding(binEntries_, total), growDiscarding(binScratch_, total);
    Entry* const entries = binEntries_.data();
    const int indexBits = indexBits_;
    tbb::parallel_for(size_t(0), chunks.count, [&, layout](size_t c) {
        uint32_t* const cursor = counts.data() + c * tiles;
        for (size_t i = chunks.begin(c), end = chunks.end(c); i < end; ++i) {
            const uint32_t o = orderOf[i];
            if (o == ProjectedWindow::kNotDrawn) continue;
            const Entry e = layout.key(o, depthOf[i]) << indexBits | i;
            forTiles(tilesOf[i], [&](size_t tile) { entries[cursor[tile]++] = e; });
        }
    });
    SkippedPrimitives skipped;
    for (const SkippedPrimitives& s : skippedIn) {
        skipped.points += s.points, skipped.splats += s.splats;
        skipped.exactIndexSplats += s.exactIndexSplats, skipped.voxels += s.voxels;
    }
    return skipped;
}

/// One tile's pixels, row-major with stride kTileSize, in the thread compositing it: the
/// hot loops touch a few KiB that stay in L1, and the image is written back once per window.
/// Structure of arrays (T, R, G, B), 64-byte aligned, so the splat loop loads whole rows.
struct TileCompositor::TilePixels {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive image rectangle of the tile
    float epsilon = kTransmittanceEpsilon;  // the compositor's cutoff (loadTile sets it)
    alignas(64) std::array<float, kTileSize * kTileSize> T;
    alignas(64) std::array<float, kTileSize * kTileSize> R;
    alignas(64) std::array<float, kTileSize * kTileSize> G;
    alignas(64) std::array<float, kTileSize * kTileSize> B;

    /// The splat being drawn (drawSplat), its fields set splat by splat: a fresh SplatRaster per
    /// splat was 168 bytes zeroed (rep stos) each time, a quarter of drawSplat's samples.
    SplatRaster raster;

    static int local(int x, int y, int x0, int y0) { return (y - y0) * kTileSize + (x - x0); }
    int local(int x, int y) const { return local(x, y, x0, y0); }
    bool live(int i) const { return T[size_t(i)] >= epsilon; }
    /// Whether any pixel has T ≥ ε, 16 pixels at a time (a live tile answers in its first 16:
    /// tile-level early termination asks every 32 primitives, and counting all 1 024 pixels each
    /// time was 70 % of compositeTile's own samples on the framed Engine).
    bool anyLive() const {
        for (size_t i = 0; i < T.size(); i += 16) {
            bool any = false;
            for (size_t j = 0; j < 16; ++j) any |= T[i + j] >= epsilon;
            if (any) return true;
        }
        return false;
    }
    /// The vector loops' view; @p grey: T and R alone (ColorChannels::Grey).
    TileBuffers buffers(bool grey) { return {T.data(), R.data(), grey ? nullptr : G.data(), grey ? nullptr : B.data(), x0, y0}; }
    /// α = 1 − exp(−τ);  C += T·α·c;  T *= 1 − α   (DESIGN §4), except that a deposit leaving
    /// T < ε takes the whole remainder: C += T·c, T = 0 (the vector loops' Over).
    void over(int i, float tau, const glm::vec3& color) {
        const float ta = takeTransmittance(T[size_t(i)], opacityFromOpticalDepth(tau), epsilon);
        R[size_t(i)] += ta * color.x;
        G[size_t(i)] += ta * color.y;
        B[size_t(i)] += ta * color.z;
    }
};

bool TileCompositor::hiddenTiles(int x0, int y0, int x1, int y1) const {
    x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, width_ - 1), y1 = std::min(y1, height_ - 1);
    if (x0 > x1 || y0 > y1) return true;
    if (liveRows_[size_t(y0) * size_t(tilesX_) + size_t(x0 / kTileSize)] >> (x0 % kTileSize) & 1u) return false;
    for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty)
        for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx)
            if (liveCount_[size_t(ty) * tilesX_ + tx] > 0 && anyLive(tx, ty, x0, y0, x1, y1)) return false;
    return true;
}

void TileCompositor::loadTile(int tile, TilePixels& px) const {
    px.x0 = (tile % tilesX_) * kTileSize, px.y0 = (tile / tilesX_) * kTileSize;
    px.epsilon = epsilon_;
    px.x1 = std::min(width_, px.x0 + kTileSize) - 1, px.y1 = std::min(height_, px.y0 + kTileSize) - 1;
    px.T.fill(0.f);  // pixels past the image's edge: finished (T = 0), never drawn
    px.R.fill(0.f), px.G.fill(0.f), px.B.fill(0.f);
    // One channel: G and B stay 0 for the scalar paths' "over" (their G and B are dropped at store).
    for (int y = px.y0; y <= px.y1; ++y)
        for (int x = px.x0; x <= px.x1; ++x) {
            const size_t i = size_t(px.local(x, y)), k = size_t(y) * width_ + x;
            px.T[i] = transmittance_[k];
            px.R[i] = color_[k].x;
            if (!grey_) px.G[i] = color_[k].y, px.B[i] = color_[k].z;
        }
}

void TileCompositor::storeTile(int tile, const TilePixels& px) {
    for (int y = px.y0; y <= px.y1; ++y)
        for (int x = px.x0; x <= px.x1; ++x) {
            const size_t i = size_t(px.local(x, y)), k = size_t(y) * width_ + x;
            transmittance_[k] = px.T[i];
            color_[k] = grey_ ? glm::vec3(px.R[i]) : glm::vec3(px.R[i], px.G[i], px.B[i]);
        }
    // Each row's live pixels as bits, and their count (pixels past the image's edge hold T = 0:
    // never live).
    const size_t tx = size_t(tile % tilesX_);
    int live = 0;
    for (int y = px.y0; y <= px.y1; ++y) {
        const float* row = px.T.data() + size_t(y - px.y0) * kTileSize;
        uint32_t bits = 0;
        for (int j = 0; j < kTileSize; ++j) bits |= uint32_t(row[j] >= epsilon_) << j;
        liveRows_[size_t(y) * size_t(tilesX_) + tx] = bits;
        live += std::popcount(bits);
    }
    liveCount_[size_t(tile)] = live;
}

namespace {
/// One "over" per pixel with the slab's summed optical depth and colour Σ τc / Σ τ, then the
/// slab is emptied (DESIGN §4). @p skipFinished: pixels already finished (T < ε) take nothing
/// (the slab order, whose slabs are composited after later primitives were deposited; in the
/// kernel order a slab's pixels were all live when it was filled and still are).
template <class Pixels, class Slab>
void compositeSlab(Pixels& px, Slab& slab, bool skipFinished = false) {
    if (!slab.dirty) return;
    // Only where deposits were made, when known (elsewhere τ = 0: nothing to composite or clear).
    const TileRect r = slab.take(px.x0, px.y0, px.x1, px.y1);
    for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) {
            const int i = y * kTileSize + x;
            const size_t j = size_t(i);
            float *tau = slab.tau() + j, *er = slab.er() + j, *eg = slab.eg() + j, *eb = slab.eb() + j;
            if (*tau > 0.f && (!skipFinished || px.live(i))) px.over(i, *tau, glm::vec3(*er, *eg, *eb) / *tau);
            *tau = 0.f, *er = 0.f, *eg = 0.f, *eb = 0.f;
        }
    slab.dirty = false;
}
}  // namespace

void TileCompositor::drawPrimitive(const TileRecord& p, uint32_t i, TilePixels& px, SlabBuffer* slab,
                                   const SlabTargets* slabs) const {
    switch (p.kind) {
        case PrimitiveKind::Point: drawPoint(p, px, slab, slabs); break;
        case PrimitiveKind::Splat: drawSplat(p, window_->exactMaps[0], px, slabs); break;  // any map: a Splat reads none
        case PrimitiveKind::SplatExactIndex:  // without its map: the half-ray fallback
            p.hasExactMap ? drawSplat(p, window_->exactMap(i, p), px, slabs) : drawExact(p, window_->extra[i], px, slabs);
            break;
        case PrimitiveKind::SplatExact:
        case PrimitiveKind::NearEye: drawExact(p, window_->extra[i], px, slabs); break;
        case PrimitiveKind::Culled: break;
    }
}

/// Records are a cache miss each (a tile's list is sparse in the window): fetch them (and, in the
/// slab order, their profiles) 8 ahead, and an exact-index splat's map (two lines) 4 ahead, once
/// its record has arrived.
inline void TileCompositor::prefetchAhead(std::span<const Entry> entries, size_t e, bool profiles) const {
    constexpr size_t kAhead = 16, kMapAhead = 8;
    // The prefetches are written out here, not in a helper lambda: GCC compiled the lambda out of
    // line, found it free of side effects and dropped its calls, as it did this whole function.
    if (e + kAhead < entries.size()) {
        __builtin_prefetch(&window_->records[indexOf(entries[e + kAhead])]);
        if (profiles) {
            const char* c = reinterpret_cast<const char*>(&window_->profile[indexOf(entries[e + kAhead])]);
            __builtin_prefetch(c), __builtin_prefetch(c + sizeof(SlabProfile) - 1);
        }
    }
    if (e + kMapAhead < entries.size() && window_->records[indexOf(entries[e + kMapAhead])].hasExactMap) {
        const char* c = reinterpret_cast<const char*>(&window_->exactMap(indexOf(entries[e + kMapAhead])));
        __builtin_prefetch(c), __builtin_prefetch(c + sizeof(ExactIndexMap) - 1);
    }
}

void TileCompositor::compositeTile(int tile, std::span<const Entry> entries) {
    TilePixels px;
    loadTile(tile, px);
    SlabBuffer slab;
    int64_t slabOf = std::numeric_limits<int64_t>::min();
    for (size_t e = 0; e < entries.size(); ++e) {
        prefetchAhead(entries, e, false);
        const uint32_t i = indexOf(entries[e]);
        const TileRecord& p = window_->records[i];
        const bool isPoint = p.kind == PrimitiveKind::Point;
        if (int64_t(p.slab) != slabOf || !isPoint) {
            closeSlab(px, slab, false);
            slabOf = p.slab;
        }
        // Tile-level early termination, checked every 32 primitives.
        if ((e & 31) == 31 && !slab.dirty && !px.anyLive()) break;
        drawPrimitive(p, i, px, &slab, nullptr);
    }
    closeSlab(px, slab, false);
    storeTile(tile, px);
}

/// --compositing slabs: each primitive's τ goes to the slabs s − K … s + K of its profile; slabs
/// before s − K are composited first, in order, and at the end every slab before @p closeBefore
/// (no later window reaches it). A tile that turned opaque composites and drops all it holds.
void TileCompositor::compositeTileSlabs(int tile, std::span<const Entry> entries, int64_t closeBefore) {
    std::unique_ptr<SlabRing>& owned = rings_[size_t(tile)];
    if (!owned) owned = std::make_unique<SlabRing>(slabs_.reach);
    SlabRing& ring = *owned;
    TilePixels px;
    loadTile(tile, px);
    const int reach = slabs_.reach;
    const auto closeUpTo = [&](int64_t end) {  // composites the open slabs before `end`
        if (ring.first >= end) return;
        if (ring.open())
            for (int64_t s = ring.first; s < end && s <= ring.last; ++s) closeSlab(px, ring.at(s), true);
        ring.first = end;
    };
    const int64_t base = window_->slabBase;
    SlabTargets targets;
    for (size_t e = 0; e < entries.size(); ++e) {
        prefetchAhead(entries, e, true);
        const uint32_t i = indexOf(entries[e]);
        const TileRecord& p = window_->records[i];
        const int64_t slab = base + int64_t(p.slab);
        closeUpTo(slab - reach);
        // Tile-level early termination, checked every 32 primitives (open slabs of finished
        // pixels add at most ε·c; they are composited below all the same).
        if ((e & 31) == 31 && !px.anyLive()) break;
        ring.targets(window_->profile[i], slab, reach, grey_, targets);
        if (targets.count > 0) drawPrimitive(p, i, px, nullptr, &targets);
    }
    closeUpTo(closeBefore);
    const bool opaque = !px.anyLive();
    if (opaque && ring.open()) closeUpTo(ring.last + 1);
    // The ring stays with its tile until finish() (its slots are empty again once composited, and
    // allocating, zeroing, 2K + 1 slabs anew for every window cost more than the tile's work),
    // unless the tile is opaque: no primitive reaches it any more (binning skips it).
    storeTile(tile, px);
    if (opaque) owned.reset();
}

void TileCompositor::closeSlab(TilePixels& px, SlabBuffer& slab, bool skipFinished) const {
    if (!slab.dirty) return;
    if (!exact_.vector) {
        compositeSlab(px, slab, skipFinished);
        return;
    }
    // The vector loop skips finished pixels too: in the kernel order there are none among a
    // slab's deposits (its points drew only live pixels, and nothing drew in between).
    compositeSlabVector(slab.tau(), slab.er(), slab.eg(), slab.eb(), px.buffers(grey_), epsilon_,
                        slab.take(px.x0, px.y0, px.x1, px.y1));
    slab.dirty = false;
}

void TileCompositor::finish() {
    if (!slabs_.on) return;
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX_ * tilesY_, 1), [&](const tbb::blocked_range<int>& r) {
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            std::unique_ptr<SlabRing>& ring = rings_[size_t(tile)];
            if (!ring) continue;
            if (ring->open()) {
                TilePixels px;
                loadTile(tile, px);
                for (int64_t s = ring->first; s <= ring->last; ++s) closeSlab(px, ring->at(s), true);
                storeTile(tile, px);
            }
            ring.reset();
        }
    });
}

void TileCompositor::drawPoint(const TileRecord& p, const TilePixels& px, SlabBuffer* slab, const SlabTargets* slabs) const {
    // The filter was set up at projection (PointSetup): only this tile's pixels are evaluated.
    PointRaster r;
    r.cx = p.centre.x, r.cy = p.centre.y;
    r.invVariance = p.shape.x, r.total = p.shape.y, r.norm = p.shape.z, r.radius2 = p.scale;
    r.color = p.color;
    r.x0 = std::max(p.range.x0, px.x0), r.x1 = std::min(p.range.x1, px.x1);
    r.y0 = std::max(p.range.y0, px.y0), r.y1 = std::min(p.range.y1, px.y1);
    r.epsilon = epsilon_;
    if (slabs) {
        exact_.vector ? drawPointSlabsVector(r, *slabs, px.T.data(), px.x0, px.y0)
                      : drawPointSlabsScalar(r, *slabs, px.T.data(), px.x0, px.y0);
        return;
    }
    const SlabTile tile{slab->tau(), slab->er(), grey_ ? nullptr : slab->eg(), grey_ ? nullptr : slab->eb(),
                        px.T.data(), px.x0, px.y0};
    exact_.vector ? drawPointVector(r, tile) : drawPointScalar(r, tile);
    if (r.x0 <= r.x1 && r.y0 <= r.y1) slab->touch(r.x0, r.y0, r.x1, r.y1);
    slab->dirty = true;
}

namespace {
/// Where the scalar paths put one pixel's τ: "over" (kernel order) or the slab sums.
template <class Pixels>
void depositAt(Pixels& px, int i, float tau, const glm::vec3& color, const SlabTargets* slabs) {
    if (!slabs) {
        px.over(i, tau, color);
        return;
    }
    for (int j = 0; j < slabs->count; ++j) {
        const float t = tau * slabs->fraction[size_t(j)];
        slabs->tau[size_t(j)][i] += t;
        slabs->er[size_t(j)][i] += t * color.x;
        if (!slabs->eg[size_t(j)]) continue;  // one channel (ColorChannels::Grey)
        slabs->eg[size_t(j)][i] += t * color.y;
        slabs->eb[size_t(j)][i] += t * color.z;
    }
}
}  // namespace

void TileCompositor::drawSplat(const TileRecord& p, const ExactIndexMap& map, TilePixels& px, const SlabTargets* slabs) const {
    const bool exactIndex = p.kind == PrimitiveKind::SplatExactIndex;
    if (exact_.vector && (exactIndex || tables_.poly.covers(p.sin2Alpha))) {
        SplatRaster& s = px.raster;
        s.cx = p.centre.x, s.cy = p.centre.y;
        s.qxx = p.shape.x, s.qxy = p.shape.y, s.qyy = p.shape.z;
        s.scale = p.scale;
        s.series = opacitySeriesFor(p.scale * tables_.poly.peak());
        s.coef = exactIndex ? tables_.poly.axisRow() : tables_.poly.row(p.sin2Alpha);
        s.exactIndex = exactIndex;
        if (exactIndex) s.map = map;
        s.color = p.color;
        s.x0 = std::max(p.range.x0, px.x0), s.x1 = std::min(p.range.x1, px.x1);
        s.y0 = std::max(p.range.y0, px.y0), s.y1 = std::min(p.range.y1, px.y1);
        s.epsilon = epsilon_;
        s.safeT = remainderBound(epsilon_, p.scale * tables_.poly.peak());
        s.slabs = slabs;
        drawSplatVector(s, px.buffers(grey_));
        return;
    }
    drawSplatTables(p, map, px, slabs);
}

void TileCompositor::drawSplatTables(const TileRecord& p, const ExactIndexMap& map, TilePixels& px, const SlabTargets* slabs) const {
    // SplatExactIndex (--footprint auto, far off the axis): the exact index d instead of the
    // affine one, from the affine map set up once at projection (ExactIndexMap).
    const bool exactIndex = p.kind == PrimitiveKind::SplatExactIndex;
    SplatShader shader;  // the table path's per-splat state (screen_kernel.h)
    shader.row = tables_.reindex.row(halfConeAngle(p.sin2Alpha));
    shader.footprint = &tables_.footprint;
    shader.scale = p.scale;
    const int x0 = std::max(p.range.x0, px.x0), x1 = std::min(p.range.x1, px.x1);
    const int y0 = std::max(p.range.y0, px.y0), y1 = std::min(p.range.y1, px.y1);
    const float qxx = p.shape.x, qxy = p.shape.y, qyy = p.shape.z;
    for (int y = y0; y <= y1; ++y) {
        const float dy = float(y) + 0.5f - p.centre.y;
        // The row's chord of the support ellipse, i² < 1:  qxx dx² + 2 qxy dy dx + qyy dy² − 1 < 0.
        // One pixel of slack on each side; the i² test below decides exactly.
        const float b = qxy * dy, disc = b * b - qxx * (qyy * dy * dy - 1.f);
        if (!(disc > 0.f)) continue;
        const float root = std::sqrt(disc);
        const float lo = p.centre.x - 0.5f + (-b - root) / qxx, hi = p.centre.x - 0.5f + (-b + root) / qxx;
        const int xa = std::max(x0, int(std::floor(lo))), xb = std::min(x1, int(std::ceil(hi)));
        const int row = (y - px.y0) * kTileSize;
        for (int x = xa; x <= xb; ++x) {
            const int i = row + (x - px.x0);
            if (!px.live(i)) continue;
            const float dx = float(x) + 0.5f - p.centre.x;
            const float i2 = qxx * dx * dx + 2.f * qxy * dx * dy + qyy * dy * dy;
            if (!(i2 < 1.f)) continue;
            const float tau = exactIndex ? shader.depositAtD2(map.d2(i2, dx, dy)) : shader.depositAtIndex2(i2);
            depositAt(px, i, tau, p.color, slabs);
        }
    }
}

void TileCompositor::drawExact(const TileRecord& p, const PrimitiveExtra& extra, TilePixels& px, const SlabTargets* slabs) const {
    const Camera& camera = *exact_.camera;
    if (exact_.shape && !exact_.shape->sphere) {  // an ellipsoid at the eye: the exact half-ray integral
        const int x0 = std::max(p.range.x0, px.x0), x1 = std::min(p.range.x1, px.x1);
        const int y0 = std::max(p.range.y0, px.y0), y1 = std::min(p.range.y1, px.y1);
        const glm::dvec3 c(extra.viewPos);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const int i = px.local(x, y);
                if (!px.live(i)) continue;
                const double tau = extra.sigma * ellipsoidHalfRayDeposit(*exact_.shape, c, camera.viewRay(PixelCoord(x + 0.5, y + 0.5)));
                if (tau > 0.0) depositAt(px, i, float(tau), p.color, slabs);
            }
        return;
    }
    const double h = exact_.voxelSize;
    const KernelShape& shape = *tables_.kernel;
    const SphereProjection sphere = projectSphere(camera, ViewPoint(extra.viewPos), shape.radius() * h);
    // Recomputed from the float view position: a borderline sphere may no longer be an
    // Ellipse, and then takes the half-ray fallback like a NearEye kernel.
    const bool widened = p.kind != PrimitiveKind::NearEye && sphere.isEllipse();
    ScreenKernel kernel;
    // The projection's low-pass, at its spacing (projectVoxel).
    if (widened) kernel = makeScreenKernel(sphere, exact_.lowPass.at(camera.spacingPx(h, extra.viewPos.z)), shape);
    const int x0 = std::max(p.range.x0, px.x0), x1 = std::min(p.range.x1, px.x1);
    const int y0 = std::max(p.range.y0, px.y0), y1 = std::min(p.range.y1, px.y1);
    const double sigmaWorld = extra.sigma / h;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const int i = px.local(x, y);
            if (!px.live(i)) continue;
            const PixelCoord q(x + 0.5, y + 0.5);
            const double tau =
                widened ? splatDepositExact(kernel, sphere, sigmaWorld, h, q, shape) : extra.sigma * halfRayFootprint(sphere, q, shape);
            if (tau > 0.0) depositAt(px, i, float(tau), p.color, slabs);
        }
}

}  // namespace vdbsplat
