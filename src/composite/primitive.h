// composite/primitive.h — the projected primitives the compositor consumes.
// Owns: Primitive, everything projection knows of one voxel (render/project.h, projectVoxel):
// a filtered point (DESIGN §4, circular pixel filter w), an EWA splat (exact
// ellipse widened by the low-pass, (i, α) reindex + footprint table), or a
// near-eye kernel drawn with the exact half-ray integral (ellipse.h fallback);
// and ProjectedWindow, a window of them as the renderer passes it on: structure of arrays
// (a 64-byte PrimitiveRecord the tiles draw, the order key's parts, the voxel count, the
// exact-index splats' maps and the rare kinds' extra data), so that each pass reads only what it
// needs (~80 B per drawn primitive written by projection instead of the ~200-byte Primitive),
// compacted block by block so that what draws nothing leaves nothing in memory.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "composite/slab_profile.h"
#include "composite/tile.h"
#include "footprint/pixel_box.h"
#include "footprint/screen_kernel.h"
#include "util/huge_pages.h"

namespace vdbsplat {

enum class PrimitiveKind : uint8_t {
    Culled = 0,    ///< off screen, behind the eye, or empty: draws nothing
    Point = 1,     ///< minified voxel: w(p − centre) with variance `variance`, total optical depth `total`
    Splat = 2,     ///< magnified voxel, table path: conic + SplatShader
    SplatExact = 3,///< magnified voxel, --footprint exact: recomputed per tile from viewPos
    SplatExactIndex = 5, ///< magnified voxel, --footprint auto, far off-axis: exact index d per pixel
                         ///< (kernel recomputed per tile from viewPos) into the footprint table
    NearEye = 4,   ///< kernel containing the eye or straddling the eye plane: exact half-ray integral
};

struct Primitive {
    // What ProjectedWindow::set reads comes first (two cache lines; the
    // exact-index map and the recompute fields after them are read only for their kinds).
    PrimitiveKind kind = PrimitiveKind::Culled;
    bool hasExactMap = false;   ///< SplatExactIndex: exactMap is set
    int64_t slab = 0;           ///< depth slab (points of one slab are summed before compositing)
    float depth = 0.f;          ///< radial distance of the voxel centre (world units): the order
    uint32_t members = 1;       ///< active voxels it stands for (a level-of-detail aggregate: more)
    PixelRange range;           ///< the image pixels it may touch (clamped)
    glm::vec3 color{0.f};       ///< emitted colour (already tinted for --show-primitives)
    glm::vec2 centre{0.f};      ///< point position / ellipse centre (pixels)
    // Point
    float variance = 0.f;       ///< V_point, px²
    float total = 0.f;          ///< Σ_pixels τ (DESIGN §4 energy rule)
    /// The filter set up once from centre and variance (pointfilter/point_filter.h, PointSetup);
    /// `range` is then its footprint clamped to the image (empty: nothing on screen).
    float pointInvVariance = 0.f, pointRadius2 = 0.f, pointNorm = 0.f;
    // Splat (table path)
    glm::vec3 conic{0.f};       ///< Q as (Qxx, Qxy, Qyy): i² = Qxx dx² + 2 Qxy dx dy + Qyy dy²
    float scale = 0.f;          ///< σ_k·h·amplitude (SplatShader::scale)
    float sin2Alpha = 0.f;      ///< sin²α: the vector loop's polynomial row, the table path's
                                ///< reindex row through halfConeAngle()
    // SplatExactIndex: the exact d² as an affine map of the pixel (δ from `centre`), set up once
    ExactIndexMap exactMap;
    // SplatExact / NearEye (recomputed from these per tile; they are rare or a diagnostic)
    glm::vec3 viewPos{0.f};
    float sigma = 0.f;          ///< extinction per voxel length
    /// --compositing slabs: the fractions of its optical depth for the slabs around its own
    /// (composite/slab_profile.h), set by projectBatch.
    SlabProfile profile;
};

/// The projected window: reused window after window, in huge pages where a window fills them
/// (util/huge_pages.h).
using PrimitiveBuffer = std::vector<Primitive, HugePageAllocator<Primitive>>;

/// What the tile loop reads of one primitive, in one 64-byte line (gsplat: sort keys, not
/// records). The rare kinds that need more read the window's PrimitiveExtra.
struct PrimitiveRecord {
    glm::vec2 centre;      ///< point position / ellipse centre (pixels)
    glm::vec3 shape;       ///< splat: conic (Qxx, Qxy, Qyy); point: (1/V, total, norm) (PointSetup)
    float scale;           ///< splat: σ·h·amplitude; point: r_s²
    float sin2Alpha;       ///< splat: the polynomial's (or the reindex table's) row
    glm::vec3 color;
    PixelRange range;
    uint32_t slab;         ///< relative to the window's first slab (ProjectedWindow::slabBase)
    PrimitiveKind kind;
    bool hasExactMap;      ///< SplatExactIndex: the window's exactMaps holds its ExactIndexMap
    /// Where: exactMaps[its block's first slot + this] (ProjectedWindow::exactMap; a block's maps
    /// are compacted as its records are).
    uint16_t exactMapSlot;
};
static_assert(sizeof(PrimitiveRecord) == 64, "one cache line per primitive");

/// What only the kernels recomputed per tile read: SplatExact, NearEye, and a SplatExactIndex
/// without its map (hasExactMap false: the half-ray fallback). An exact-index splat with its map
/// reads the map alone (ProjectedWindow::exactMaps, 24 bytes: two thirds of the framed checker
/// box's splats are such, and this struct beside the map was 16 bytes more of fresh memory each).
struct PrimitiveExtra {
    glm::vec3 viewPos{0.f};
    float sigma = 0.f;
};
/// Whether a primitive of @p kind reads its PrimitiveExtra (@p hasExactMap: the record's).
inline bool needsExtra(PrimitiveKind kind, bool hasExactMap) {
    return kind == PrimitiveKind::SplatExact || kind == PrimitiveKind::NearEye ||
           (kind == PrimitiveKind::SplatExactIndex && !hasExactMap);
}

/// The tiles of a clamped, non-empty pixel range, 16 bits each (images ≤ 16384 px: ≤ 512 tiles a
/// side): first column, first row, last column, last row from the low bits up.
inline uint64_t tileRect(const PixelRange& r) {
    return uint64_t(r.x0 / kTileSize) | uint64_t(r.y0 / kTileSize) << 16 | uint64_t(r.x1 / kTileSize) << 32 |
           uint64_t(r.y1 / kTileSize) << 48;
}

/// A window of primitives, structure of arrays. Compacted by blocks: the window's voxels
/// [b·kBlock, (b + 1)·kBlock) give block b's slots, its drawn primitives first, in voxel order,
/// and the rest of the block's slots not drawn (only their `order` is set: kNotDrawn). So a
/// primitive that draws nothing (culled, off screen, or behind finished pixels) leaves no record
/// in memory, and the order of the drawn ones, which the compositor's sort breaks ties by, is the
/// voxels' order. Reused window after window (the buffers grow only), in huge pages where a
/// window fills them.
struct ProjectedWindow {
    /// Voxels per compaction block: the projection's unit of work, too (one thread a block).
    static constexpr size_t kBlock = 1024;
    template <class T>
    using Buffer = std::vector<T, HugePageAllocator<T>>;
    /// `order` of a primitive that draws nothing (culled, or no pixel on screen).
    static constexpr uint32_t kNotDrawn = UINT32_MAX;
    /// Slabs are kept relative to slabBase below this (2^27, as the compositor's sort key).
    static constexpr int64_t kMaxRelativeSlab = (int64_t(1) << 27) - 1;

    size_t size = 0;
    int64_t slabBase = 0;              ///< the first slab: records' and order's slabs are relative to it
    int64_t slabEnd = 0;               ///< one past the window's last slab (the next window starts there or later)
    /// --compositing slabs: each primitive's slab fractions are kept (profile[i]); false: not written.
    bool profiles = false;
    Buffer<PrimitiveRecord> records;
    Buffer<uint32_t> order;            ///< the sort key's high part: relative slab·2 + (not a point), or kNotDrawn
    Buffer<float> depth;               ///< radial distance of the voxel centre (world units): the order in a slab
    Buffer<uint32_t> members;          ///< active voxels each stands for
    /// The screen tiles (composite/tile.h) a drawn primitive's range covers, packed (tileRect):
    /// what the compositor's binning reads, 8 bytes instead of the record's line. Unset where
    /// order is kNotDrawn.
    Buffer<uint64_t> tiles;
    /// The exact-index splats' maps, block by block: a block's maps fill its slots from the front
    /// (exactMap(i)), so a window with few of them touches few pages of it.
    Buffer<ExactIndexMap> exactMaps;
    Buffer<PrimitiveExtra> extra;      ///< written only where needsExtra(kind, hasExactMap)
    Buffer<SlabProfile> profile;       ///< written only when `profiles`

    /// Grows the buffers to @p n primitives (contents undefined until set()).
    void resize(size_t n) {
        growDiscarding(records, n), growDiscarding(order, n), growDiscarding(depth, n);
        growDiscarding(members, n), growDiscarding(exactMaps, n), growDiscarding(extra, n), growDiscarding(tiles, n);
        if (profiles) growDiscarding(profile, n);
        size = n;
    }
    /// The ExactIndexMap of primitive @p i, whose record @p r is (r.hasExactMap).
    const ExactIndexMap& exactMap(size_t i, const PrimitiveRecord& r) const { return exactMaps[i / kBlock * kBlock + r.exactMapSlot]; }
    const ExactIndexMap& exactMap(size_t i) const { return exactMap(i, records[i]); }
    /// Where primitive @p i's map goes: exactMaps[@p map], which must lie in i's block; its record
    /// is told (exactMapSlot). The caller writes the map there.
    ExactIndexMap& mapSlotFor(size_t i, size_t map) {
        records[i].exactMapSlot = uint16_t(map % kBlock);
        return exactMaps[map];
    }
    /// Stores @p p as primitive @p i (its slab relative to slabBase, clamped to [0, kMaxRelativeSlab]),
    /// its map (if it has one) in exactMaps[@p map], which must lie in i's block (the projection
    /// passes its block's next free map slot; by default the map lies beside the record, at i).
    void set(size_t i, const Primitive& p) { set(i, p, i); }
    void set(size_t i, const Primitive& p, size_t map) {
        const bool point = p.kind == PrimitiveKind::Point;
        PrimitiveRecord& q = records[i];
        q.centre = p.centre;
        q.shape = point ? glm::vec3(p.pointInvVariance, p.total, p.pointNorm) : p.conic;
        q.scale = point ? p.pointRadius2 : p.scale;
        q.sin2Alpha = p.sin2Alpha;
        q.color = p.color;
        q.range = p.range;
        q.kind = p.kind;
        q.hasExactMap = p.hasExactMap;
        place(i, p.slab, p.depth, p.members, p.kind, p.range);
        if (p.hasExactMap) mapSlotFor(i, map) = p.exactMap;
        if (needsExtra(p.kind, p.hasExactMap)) extra[i] = PrimitiveExtra{p.viewPos, p.sigma};
        if (profiles) profile[i] = p.profile;
    }
    /// The rest of primitive @p i once records[i] holds all but its slab (set() does this; the
    /// projection's lane path writes its splats' records in place and then calls this, without
    /// building a Primitive: a record built aside and copied stalled on store forwarding):
    /// its slab @p absoluteSlab, its order key, @p distance and @p voxels. @p kind and @p range
    /// are the record's, passed in: read back from the record just stored, they waited on its
    /// store (docs/performance.md, session 38).
    void place(size_t i, int64_t absoluteSlab, float distance, uint32_t voxels, PrimitiveKind kind, const PixelRange& range) {
        const uint32_t slab = uint32_t(std::clamp<int64_t>(absoluteSlab - slabBase, 0, kMaxRelativeSlab));
        records[i].slab = slab;
        const bool drawn = kind != PrimitiveKind::Culled && !range.empty();
        order[i] = drawn ? slab << 1 | (kind == PrimitiveKind::Point ? 0u : 1u) : kNotDrawn;
        if (drawn) tiles[i] = tileRect(range);
        depth[i] = distance;
        members[i] = voxels;
    }
};

/// @brief The half cone angle α = asin(sin α) of a splat from its stored sin²α (DESIGN §2):
/// the table path's reindex row; the projection itself needs no trigonometry.
inline double halfConeAngle(float sin2Alpha) { return std::asin(std::sqrt(std::clamp(double(sin2Alpha), 0.0, 1.0))); }

}  // namespace vdbsplat
