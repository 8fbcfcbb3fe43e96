// composite/compositor.h — the one EWA-filtered, front-to-back compositor (DESIGN §4, §5).
// Owns: the frame (premultiplied colour and transmittance per pixel), binning a window's
// primitives to square screen tiles (composite/tile.h), ordering each tile's list by a
// (slab, kind, depth, index) key (packed keys, sorted in the tile's own task), and
// compositing every tile's list independently and in parallel:
//   - points of one slab are summed into a slab buffer (optical depth and
//     σ-weighted colour) and composited when the slab ends, so side-by-side
//     points never occlude each other;
//   - splats are composited one by one ("over") after the points of their slab;
//   - α = 1 − exp(−τ), C += T·α·c, T *= 1 − α, except that the deposit that
//     takes T below ε takes all of it, C += T·c, T = 0 (the remainder:
//     takeTransmittance, composite/opacity.h; docs/compositing.md);
//   - a pixel whose T < ε takes no more work; a tile whose pixels all have
//     T < ε takes no more primitives, and blocks hidden behind such tiles are
//     never streamed (hidden()).
// With --compositing slabs (SlabCompositing, docs/compositing.md) every primitive instead deposits
// its optical depth and σ-weighted colour into the slabs its kernel spans (its SlabProfile), each
// tile keeps the slabs still open in a ring that persists from window to window, and a slab is
// composited once ("over" with the summed τ) as soon as no later primitive can reach it.
// The order inside a tile is a total order independent of threads, so the image
// does not depend on the thread count.
#pragma once
#include <algorithm>
#include <memory>
#include <span>
#include <vector>

#include "composite/compositing.h"
#include "composite/primitive.h"
#include "composite/tile.h"
#include "footprint/ellipse.h"
#include "footprint/ellipsoid.h"
#include "footprint/prefilter.h"
#include "footprint/tables.h"
#include "image/image.h"
#include "pointfilter/point_filter.h"
#include "util/huge_pages.h"

namespace vdbsplat {

/// Transmittance below which a pixel is finished (early termination), by default
/// (composite/compositing.h). A render may raise it (RenderSettings::cutoff, --cutoff).
inline constexpr float kTransmittanceEpsilon = float(kDefaultCutoff);

/// @brief What the exact and near-eye paths need to recompute a kernel per tile.
struct ExactContext {
    const Camera* camera = nullptr;
    double voxelSize = 1.0;
    /// Splats through the vector loop (composite/splat_raster.h, polynomial footprint); false:
    /// the scalar table path, the oracle it is tested against.
    bool vector = true;
    /// The low-pass folded into kernels recomputed per tile, by their projected spacing (px²; as
    /// ProjectionContext::lowPass).
    PrefilterRamp lowPass{};
    /// The kernels' shape in view space (footprint/ellipsoid.h); null or a sphere: spheres.
    /// Ellipsoid kernels at the eye (NearEye) take the exact index-space half-ray integral.
    const VoxelShape* shape = nullptr;
};

/// Primitives composite() dropped because every tile they touch is already opaque.
struct SkippedPrimitives {
    uint64_t points = 0, splats = 0;
    uint64_t exactIndexSplats = 0;  ///< of the splats: SplatExactIndex
    uint64_t voxels = 0;            ///< active voxels the skipped primitives stand for
};

/// @brief The compositor's large buffers. A caller rendering many images (bench, animate,
/// study: render/hybrid.h, ForwardBuffers) keeps them from one render to the next, so their
/// pages are faulted in once, not once per render. They grow and never shrink, and each is
/// written before it is read, so an image never depends on what they held before.
struct CompositorBuffers {
    template <class T>
    using Buffer = std::vector<T, HugePageAllocator<T>>;
    Buffer<glm::vec3> color;        ///< the frame: premultiplied radiance
    Buffer<float> transmittance;    ///< the frame: T
    Buffer<uint64_t> binEntries;    ///< per tile: sort entries (key above window index)
    Buffer<uint64_t> binScratch;    ///< per tile: its sort's second buffer (same offsets)
    std::vector<uint32_t> binCounts;
    std::vector<size_t> binStart;
};

class TileCompositor {
public:
    /// @param buffers where the large buffers live (kept by the caller across renders); null: its own.
    /// @param channels Grey: every primitive's colour is grey (ColorChannels); taken with the vector
    /// loops, else (the scalar oracle) the compositor carries all three.
    /// @param cutoff ε: a pixel whose transmittance falls below it takes nothing more (> 0).
    TileCompositor(int width, int height, const Tables& tables, const ExactContext& exact, SlabCompositing slabs = {},
                   CompositorBuffers* buffers = nullptr, ColorChannels channels = ColorChannels::Rgb,
                   float cutoff = kTransmittanceEpsilon);
    ~TileCompositor();

    /// @brief Composites @p window (one depth window, any order) behind everything before.
    /// @return the primitives skipped because every tile they touch is opaque.
    SkippedPrimitives composite(const ProjectedWindow& window, double& binSeconds, double& compositeSeconds);
    /// @brief The same for primitives one by one (tests): packed into a ProjectedWindow first.
    SkippedPrimitives composite(std::span<const Primitive> prims, double& binSeconds, double& compositeSeconds);

    /// @brief True if every pixel of the inclusive rectangle (clamped to the image) is already
    /// opaque (T < ε): tiles with no live pixel are passed whole, the others pixel by pixel, so a
    /// block or primitive on the dead side of a tile that straddles a silhouette is caught too.
    /// A rectangle wholly off the image covers no pixel, so it is hidden (it would draw nothing).
    /// Most rectangles' first pixel is still live (one bit of the live rows): answered here, inline
    /// (the projection asks for every primitive, and the call was 2–5 % of a framed view's time).
    bool hidden(int x0, int y0, int x1, int y1) const {
        if (x0 >= 0 && y0 >= 0 && x0 < width_ && y0 < height_ && x0 <= x1 && y0 <= y1 &&
            (liveRows_[size_t(y0) * size_t(tilesX_) + size_t(x0 / kTileSize)] >> (x0 % kTileSize) & 1u))
            return false;
        return hiddenTiles(x0, y0, x1, y1);
    }

    /// @brief As hidden(), the whole test (not inline).
    bool hiddenTiles(int x0, int y0, int x1, int y1) const;

    /// @brief True when some pixel of the inclusive rectangle (clamped to the image) is finished
    /// (T < ε) or the rectangle reaches past the image: tile by tile, a tile's live count against
    /// its pixels in the image. Cheap; asks whether a finer hidden() test of parts of the rectangle
    /// can pay.
    bool partlyHidden(int x0, int y0, int x1, int y1) const {
        if (x0 < 0 || y0 < 0 || x1 >= width_ || y1 >= height_) return true;
        for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty) {
            const int rows = std::min(kTileSize, height_ - ty * kTileSize);
            for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx)
                if (liveCount_[size_t(ty) * tilesX_ + tx] < rows * std::min(kTileSize, width_ - tx * kTileSize)) return true;
        }
        return false;
    }

    /// @brief Composites every slab still open (--compositing slabs: the last windows' slabs wait
    /// for the next window's primitives, whose kernels may reach back into them). Call it after
    /// the last window; nothing to do in the kernel order.
    void finish();

    /// @brief The colour channels the vector loops carry: 1 (ColorChannels::Grey taken) or 3.
    int channels() const { return grey_ ? 1 : 3; }

    /// @brief The image so far: premultiplied colour, alpha = 1 − T (after finish(): everything).
    Image image() const;
    /// @brief The same frame, in place (valid while the compositor and its buffers are).
    FrameView frame() const { return {color_.data(), transmittance_.data(), width_, height_}; }

private:
    /// Whether a pixel of tile (@p tx, @p ty) inside the inclusive rectangle has T ≥ ε: the
    /// rectangle's columns of the tile as a bit mask against each of its rows' live bits.
    bool anyLive(int tx, int ty, int x0, int y0, int x1, int y1) const {
        const int ya = std::max(y0, ty * kTileSize), yb = std::min(y1, ty * kTileSize + kTileSize - 1);
        const int xa = std::max(x0, tx * kTileSize) - tx * kTileSize, xb = std::min(x1, tx * kTileSize + kTileSize - 1) - tx * kTileSize;
        static_assert(kTileSize == 32, "a tile row's live pixels are one 32-bit word");
        const uint32_t columns = (~uint32_t(0) >> (31 - (xb - xa))) << xa;  // bits xa … xb
        for (int y = ya; y <= yb; ++y)
            if (liveRows_[size_t(y) * size_t(tilesX_) + size_t(tx)] & columns) return true;
        return false;
    }
    /// A sort entry: the key (slab (relative) · kind · depth bits) above the primitive's index
    /// (the tie-break) in one word, key << indexBits_ | index: its value order is the (key, index) order.
    using Entry = uint64_t;
    uint32_t indexOf(Entry e) const { return uint32_t(e & ((uint64_t(1) << indexBits_) - 1)); }
    /// What the tile loop reads of one primitive (PrimitiveRecord, one 64-byte line), in place in
    /// the window. The rare kinds that need more (SplatExact, NearEye) read the window's extra.
    using TileRecord = PrimitiveRecord;
    struct SlabBuffer;
    struct SlabRing;    // --compositing slabs: one tile's open slabs, kept from window to window
    struct TilePixels;  // one tile's transmittance and colour, copied in and out (thread-local)
    SkippedPrimitives binWindow(const ProjectedWindow& window);
    void loadTile(int tile, TilePixels& px) const;
    void storeTile(int tile, const TilePixels& px);
    /// Always inlined: out of line GCC finds it free of side effects (prefetches do not count)
    /// and deletes every call, which silently cost the tile loop 15 % (session 6).
    [[gnu::always_inline]] inline void prefetchAhead(std::span<const Entry> entries, size_t e, bool profiles) const;
    void compositeTile(int tile, std::span<const Entry> entries);
    void compositeTileSlabs(int tile, std::span<const Entry> entries, int64_t closeBefore);
    /// One "over" per pixel the slab deposited into (live ones only with @p skipFinished; the vector
    /// loop skips finished pixels always), then empty: over its tracked rectangle, else the tile.
    void closeSlab(TilePixels& px, SlabBuffer& slab, bool skipFinished) const;
    void drawPrimitive(const TileRecord& p, uint32_t i, TilePixels& px, SlabBuffer* slab, const SlabTargets* slabs) const;
    void drawPoint(const TileRecord& p, const TilePixels& tile, SlabBuffer* slab, const SlabTargets* slabs) const;
    void drawSplat(const TileRecord& p, const ExactIndexMap& map, TilePixels& tile, const SlabTargets* slabs) const;
    void drawSplatTables(const TileRecord& p, const ExactIndexMap& map, TilePixels& tile, const SlabTargets* slabs) const;
    void drawExact(const TileRecord& p, const PrimitiveExtra& extra, TilePixels& tile, const SlabTargets* slabs) const;

    int width_, height_, tilesX_, tilesY_;
    const Tables& tables_;
    ExactContext exact_;
    SlabCompositing slabs_;
    float epsilon_;  // the cutoff ε: T < ε is finished
    bool grey_;  // ColorChannels::Grey taken: the vector loops composite T and R, storeTile copies R to G and B
    std::vector<std::unique_ptr<SlabRing>> rings_;  // --compositing slabs: per tile, null while none is open
    template <class T>
    using Buffer = CompositorBuffers::Buffer<T>;  // large: in huge pages (util/huge_pages.h)
    std::unique_ptr<CompositorBuffers> own_;  // the buffers, unless the caller keeps them
    CompositorBuffers& kept_;             // own_ or the caller's
    Buffer<glm::vec3>& color_;            // premultiplied radiance (the first width·height)
    Buffer<float>& transmittance_;
    std::vector<int> liveCount_;          // per tile: pixels with T ≥ ε
    std::vector<uint32_t> liveRows_;      // per image row and tile column: bit j, pixel j of the tile's row has T ≥ ε
    const ProjectedWindow* window_ = nullptr;  // the window being composited (composite()'s argument)
    ProjectedWindow packed_;              // composite(span<const Primitive>)'s window
    int indexBits_ = 0;                   // the low bits of an Entry that hold the index
    int keyBits_ = 0;                     // the key's width above them (KeyLayout::bits)
    std::vector<size_t>& binStart_;       // per tile (+1): its list in binEntries_
    Buffer<Entry>& binEntries_;           // per tile: sort entries, in index order until the tile sorts them
    Buffer<Entry>& binScratch_;           // per tile: the tile sort's second buffer
    std::vector<uint32_t>& binCounts_;    // binWindow's per-(chunk, tile) counts and cursors
};

}  // namespace vdbsplat
