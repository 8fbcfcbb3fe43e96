// volume/stream.h — depth-ordered streaming of classified active voxels (DESIGN §5).
// Owns: VoxelStream, which walks the sparse tree (leaves, and active tiles split
// into 8³ blocks — never a dense copy), culls blocks behind the eye, outside the
// view frustum (kernel radius and prefilter as margin) or hidden behind opaque
// screen tiles, sorts the rest by their nearest distance to the eye, and releases
// voxels front to back in depth windows made of whole one-voxel slabs of radial
// distance. Memory holds only the voxels of blocks that straddle the current front.
//
// Each voxel comes out classified (σ per voxel length, colour) and in view space;
// voxels with σ = 0 are dropped here, so nothing downstream pays for them.
//
// Level of detail (DESIGN §8.2): a block whose voxels all project well under a pixel
// (and under the point threshold, so every one of them would be a point anyway) is
// released as aggregates of 2³, 4³ or 8³ voxels instead: one record per cell that
// carries the cell's total optical-depth mass Σσ_k and σ-weighted colour, sits at the
// σ-weighted centroid, and adds to the point filter's variance (`spread`) the projected second
// moment of its voxels about that centroid beyond a full cell's own. A block passes from one
// level to the next gradually as the camera moves, drawn at both with each cell's optical depth
// split between them (StreamOptions::lodBlend), so a zoom does not pop. Energy is kept exactly;
// what an aggregate loses is the ordering of its own voxels in depth (measured in
// docs/fidelity.md, docs/animation.md).
#pragma once
#include <array>
#include <atomic>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <utility>
#include <vector>

#include "camera/camera.h"
#include "util/huge_pages.h"
#include "volume/grid.h"
#include "volume/leaf_moments.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

class VoxelShader;     // shading/shading_field.h
class EmissionSource;  // volume/emission.h

/// @brief One depth window of voxels, structure of arrays, in a deterministic order. The arrays
/// do not zero what they grow by (HugePageAllocator: every element is written before it is read),
/// so a window's resize costs no serial pass over its memory.
struct VoxelBatch {
    template <class T>
    using Array = std::vector<T, HugePageAllocator<T>>;
    Array<glm::vec3> viewPos;  ///< voxel centre in view space (eye at origin, +z forward)
    Array<float> distance;     ///< |viewPos|, world units
    Array<float> sigma;        ///< extinction per voxel length (σ_k·h; × its weight when blended)
    Array<glm::vec3> color;    ///< emitted colour c_k (σ-weighted mean for an aggregate)
    Array<float> spread;       ///< aggregate: projected second moment about the centroid
                               ///< beyond a full cell's, isotropic (trace/2), px²; 0 for a voxel
    Array<float> depthSpread;  ///< aggregate: σ-weighted variance of its voxel centres along the
                               ///< view ray (world²), the whole second moment; 0 for a voxel.
                               ///< Only with withDepthSpread (the slab order reads it); else empty
    Array<uint32_t> members;   ///< voxels the record stands for (1, or an aggregate's count;
                               ///< 0 for the lighter of a blended block's two levels)
    bool withDepthSpread = false;    ///< depthSpread is kept (StreamOptions::depthSpread)
    int64_t slabBegin = 0;           ///< first slab of the window: slab = floor(distance / (h·slabThickness))
    int64_t slabEnd = 0;             ///< one past the last slab
    size_t size() const { return viewPos.size(); }
    void clear();           ///< empties every array, keeping their capacity
    void resize(size_t n);  ///< every array to @p n records (resizeWritten: advised for huge pages where large)
    void reserve(size_t n, bool depthSpreads);  ///< room for @p n records in every array (no pages touched)
};

/// @brief A run of a StreamWindow's records: records [begin, begin + count) of a buffer (a block's
/// in its extraction chunk, or a stretch of the pending records), window records [first, first + count).
struct WindowSource {
    const VoxelBatch* records = nullptr;
    size_t begin = 0;
    size_t first = 0;  ///< the window's index of its first record
    size_t count = 0;
};

/// @brief One depth window of voxels, read where they are (docs/performance.md, session 43): the
/// runs of the stream's buffers it takes whole, in order, instead of a copy of them in one batch.
/// The same records, in the same order, as the VoxelBatch that VoxelStream::next(VoxelBatch&)
/// copies out of it. Valid until the next next().
struct StreamWindow {
    std::vector<WindowSource> sources;
    size_t size = 0;
    int64_t slabBegin = 0, slabEnd = 0;  ///< as VoxelBatch's
    /// The window of all of @p batch (its slabs), in runs of at most @p piece records.
    static StreamWindow of(const VoxelBatch& batch, size_t piece = 1024);
    /// Copies the window's records into @p batch, in order (withDepthSpread as @p depthSpread).
    void copyTo(VoxelBatch& batch, bool depthSpread) const;
};

/// Level of detail: the largest spread a uniform cell would add, s²(n² − 1)/12, as a fraction of
/// the filter variance of the points it replaces. An aggregate keeps the energy and the second
/// moment, but not the order of its voxels in depth nor the lumps of their separate footprints;
/// where the cell is small beside the filter neither shows. 1.25 (session 20; it was 0.75 from
/// session 3, when an aggregate still added its whole second moment: ratios 1.1–2.3 then cost
/// −0.4…−8.7 dB). Since session 5 a cell adds only what exceeds a full cell's own moment, and
/// against the `--spp 16` references (400², docs/performance.md, session 20) 1.25 takes the
/// Engine's far view from blended 4³/8³ cells (31 277 points) to 8³ cells (4 435) at +0.32 dB,
/// the checker box far +0.85 dB, the tubes +0.61 dB, Marschner–Lobb the same; the checker box at
/// --distance 6 loses 0.98 dB (57.83 → 56.85, 4³ instead of 2³ cells; without level of detail
/// 53.84). Above ~1.2 the cell size (--lod) decides at these views; a larger --lod costs 0.8–11 dB.
inline constexpr double kLodMaxSpreadRatio = 1.25;
/// Level of detail, blended: passage k (ℓ from .first to .second, ℓ = the admissible level of a
/// block, log₂ of the cell size in voxels) takes a block from level k − 1 to level k (voxels,
/// 2³, 4³, 8³). The first starts where 2³ becomes admissible and is long (a zoom passes it over
/// several frames: 2³ cells are about a pixel, and coarser or quicker they flicker more); the
/// others end where the switching rule switches, so past the first a block costs at most the
/// switching rule's records plus those of its lighter level (docs/performance.md, session 5).
inline constexpr std::pair<double, double> kLodPassage[3] = {{1.0, 1.75}, {1.75, 2.0}, {2.25, 3.0}};

/// How a block passes from one level of detail to the next as its ℓ grows (kLodPassage).
enum class LodBlend : uint8_t {
    /// Every passage blended: no cell pops during a zoom (`animate`'s default).
    On,
    /// Every level switches at once where it becomes admissible (the rule before session 5).
    Off,
    /// The first passage switches at once (a block is 2³ cells from ℓ = 1), the later ones blend:
    /// the default for still images. The first passage exists only so that a zoom does not pop;
    /// a still image drawn there voxel by voxel is no closer to the reference (0 to −3.7 dB on the
    /// fidelity table's far views) and costs up to 7.5× the points (the checker box at 1024²:
    /// 712 372 against 94 328). The later passages do help still images (the far Engine loses
    /// 1.07 dB with them switched), and cost at most the switching rule's records plus a lighter level's.
    Still,
};

struct StreamOptions {
    double slabThickness = 1.0;  ///< slab thickness in voxels (points are summed within one slab)
    int slabsPerWindow = 8;      ///< a window is this many slabs (more when they are nearly empty)
    size_t minWindowVoxels = 1 << 15;  ///< grow the window until it holds about this many voxels
    /// Narrow the window (down to one slab) while windows hold more than this many voxels,
    /// widen it again (up to slabsPerWindow) when they hold under a quarter: the projected
    /// window is the renderer's largest buffer (~400 B per voxel over the projection and the
    /// compositor). Window boundaries are slab boundaries, so the image does not depend on this.
    /// 2^17 (it was 2^20): a 10⁸-voxel cloud at 1920×1080 peaks at 1.44× the loaded grid instead
    /// of 2.04×, in the same time (docs/performance.md, session 4).
    size_t maxWindowVoxels = 1 << 17;
    double screenMargin = 4.0;   ///< pixels of margin around the image for frustum culling
    /// Level of detail: aggregate cells of 2^L voxels per side whose side projects to at most
    /// this many pixels (0: off). Only blocks whose voxels are all points are aggregated, and
    /// only while the spread a cell adds stays within kLodMaxSpreadRatio of the variance of the
    /// points it replaces (pointFilterVariance with the pass's low-pass below).
    double lodCellPx = 1.0;
    /// A second cap for the levels past 2³ cells (4³ and 8³), still images only (LodBlend Still
    /// and Off): once a block's level is admissible under lodCellPx (ℓ ≥ 1), ℓ may rise to what
    /// this cap admits (within the same spread bound). 0, or not above lodCellPx: one cap. Opt-in
    /// (`--lod PX,PX2`): smooth content (CT, the Engine, the Bonsai) gains 1–3.6 dB and far views
    /// draw up to 3× fewer points with 1.5, but sharp-edged opaque content loses up to 6 dB
    /// (the checker box; docs/performance.md, session 41). Blended zooms (On) ignore it: their
    /// first passage would jump.
    double lodCoarseCellPx = 0.0;
    /// Level of detail, blended (docs/performance.md, "Level of detail"): On, a block passes from
    /// one level to the next continuously as the camera moves, drawn at both with its optical depth
    /// split between them, so no cell pops during a zoom; Off, the level switches at once where
    /// it becomes admissible (the rule before session 5); Still, the first passage switches and the
    /// later ones blend (`--lod-blend`, RenderSettings::effectiveLodBlend).
    LodBlend lodBlend = LodBlend::On;
    /// Blended, voxels → 2³: each 2³ cell passes over this fraction of its block's passage, placed
    /// by a hash of the cell, so only that fraction of a passing block is drawn twice (1: all).
    double lodVoxelRamp = 0.1;
    /// The low-pass folded into each point (px²: V_h, or V_s on the postfilter's sub-pixel grid).
    double pointPrefilterVariance = 1.0;
    /// Voxels whose projected spacing h·f/z is under this many pixels are drawn as points by
    /// the renderer (hybrid: its threshold τ; point mode: +∞; splat mode: 0, no aggregates).
    double pointBelowPx = 0.0;
    /// Whole-leaf aggregates (8³ cells) through the vectorised sums (volume/leaf_moments.h);
    /// false: the scalar row sums they are tested against (same moments to float rounding).
    bool vectorLeafMoments = true;
    /// Level-of-detail cells' records through the vectorised form (volume/cell_records.h); false:
    /// one cell at a time, the oracle (the same records, bit for bit).
    bool vectorCells = true;
    /// Plain leaves' voxels through the vectorised extraction (volume/leaf_extract.h); false: the
    /// voxel-by-voxel path it is tested against (the same records, bit for bit).
    bool vectorExtract = true;
    /// Shaded leaves' factors a whole leaf at once (VoxelShader::shadeLeaf, shading/shade_leaf.h);
    /// false: voxel by voxel (shadeDrawn), the oracle (the same factors, bit for bit).
    bool vectorShading = true;
    /// With an occlusion test (next()'s partlyHidden): a leaf drawn voxel by voxel whose screen
    /// rectangle is partly behind finished pixels is tested octant by octant (4³ voxels), and the
    /// hidden octants are neither classified nor projected (counted as occluded). False: the whole
    /// leaf is extracted and its hidden voxels dropped after projection. The same image either way.
    bool octantCulling = true;
    /// Keep the level-of-detail moments in the buffers (StreamBuffers::moments) for the next render
    /// of the same grid and table: set by renders that pass buffers kept between them (bench,
    /// animate, study). Off for a single render, which would only fill it. Not with shading or
    /// emission (their terms depend on the camera's eye).
    bool keepMoments = false;
    /// Each record's depth spread (VoxelBatch::depthSpread) for the slab order's profiles; off,
    /// the array is left empty: 4 bytes less per voxel to write and move (the 10⁸ cloud's stream
    /// spent 0.3 s on it, session 6).
    bool depthSpread = false;
};

/// @brief Counts of what the stream released and what it culled, by cause.
struct StreamCounts {
    uint64_t frustum = 0;     ///< voxels of blocks outside the view frustum or behind the eye
    uint64_t occluded = 0;    ///< voxels of blocks behind opaque screen tiles (never classified)
    uint64_t aggregates = 0;  ///< level-of-detail records released
    uint64_t aggregatedVoxels = 0;  ///< active voxels they stand for (σ = 0 voxels excluded)
};

/// @brief Level-of-detail cell moments kept from one render to the next (StreamOptions::
/// keepMoments: bench, animate, study). A block's moments depend on its voxels and the transfer
/// function, not on the camera, so a far frame after the first need not classify its voxels
/// again: the O(voxels) part of a far view. Keyed by the grid and the baked table (`key`); a
/// block's cells at level 2 (4³ cells: 8 per block) and 3 (1), and at level 1 (64) where the
/// grid's blocks fit kLevel1Budget. Each slot holds exactly what VoxelStream computes for it, so
/// an image never depends on whether it came from here.
struct LodMomentCache {
    static constexpr size_t kLevel1Budget = size_t(64) << 20;  ///< bytes for the level-1 cells, at most
    uint64_t key = 0;        ///< the grid and table the slots belong to (0: none yet)
    size_t blocks = 0;       ///< block ids (StreamBlock::id) the slots are for
    bool level1 = false;     ///< level 1 kept (the blocks fit the budget)
    /// Per level 1–3, the cells with mass only (PackedCells), each filled block's packed together
    /// from offset[id] on, in the order its extraction claimed room (cursor); the pool has room for
    /// min(every block's every cell, the active voxels) but is not initialised, so only the room
    /// claimed touches pages. (The Engine at --distance 8, level 2: 26 842 of 35 584 cells, 1.5 MB
    /// instead of 2.0; at --distance 3, level 1: 182 527 of 284 672, 10.2 MB instead of 15.9.)
    std::vector<CellMoments, HugePageAllocator<CellMoments>> cells[3];
    std::vector<uint32_t> offset[3];    ///< per level and block id: its first cell in cells[level − 1]
    std::vector<uint64_t> mask[3];      ///< per level and block id: which of its cells have mass
    std::vector<uint8_t> have[3];       ///< per level and block id: the slot is filled
    std::unique_ptr<std::atomic<size_t>[]> cursor = std::make_unique<std::atomic<size_t>[]>(3);  ///< per level: cells claimed
};

/// @brief The cells of a block with mass (Σσ > 0 or a voxel counted): cell i of the block
/// ((cx·c + cy)·c + cz) is present iff bit i of @p mask is set, and is cells[j], j the number of
/// set bits below i (packed), or cells[i] (every cell of the block in place).
struct PackedCells {
    const CellMoments* cells = nullptr;
    uint64_t mask = 0;
    bool packed = true;
    /// The present cell of bit @p i, the @p j-th present one.
    const CellMoments& at(int i, int j) const { return cells[packed ? j : i]; }
};

/// @brief One block of the stream (VoxelStream's unit of culling, ordering and level of detail): a
/// leaf, or 8³ voxels of an active tile.
struct StreamBlock {
    openvdb::Coord origin;          ///< min index corner
    int dim;                        ///< side in voxels (8)
    const openvdb::FloatTree::LeafNodeType* leaf;  ///< nullptr: an active tile block of tileValue
    float tileValue;
    float dMin, dMax;               ///< distance range of its voxel centres (world)
    uint32_t voxels;                ///< active voxels
    int lodLevel;                   ///< 0: voxel by voxel; L ≥ 1: aggregates of (2^L)³ cells
    float lodFine;                  ///< blended: 1 − t, t the passage to lodLevel from lodLevel − 1 (0: lodLevel alone)
    uint32_t id;                    ///< its place in the grid's leaf-then-tile order (the same every render)
    bool pointsOnly = false;        ///< every voxel projects under pointBelowPx: all its records are points
};

/// @brief The block list VoxelStream builds for every render and what it builds it with (the
/// leaves, their counts, the frustum test, the sort's keys), emptied and refilled each time. Kept
/// with the other buffers, a second render of the grid allocates none of them: the Engine's 4 448
/// blocks are 250 KB, fresh pages (71 faults, 0.7 ms of a 2.5 ms far render) when each render
/// allocated its own (docs/performance.md, session 46).
struct StreamBlocks {
    /// The tree `all` was listed from, with its active voxel and leaf counts: a render of the same
    /// live tree keeps the list (the leaves, their counts, the active tiles' blocks: the grid's
    /// topology) and computes only what the view decides (VoxelStream::collectBlocks). Expired or
    /// another tree: listed again. A tree edited in place between renders must not keep its list.
    std::weak_ptr<const openvdb::FloatTree> listedTree;
    uint64_t listedVoxels = 0, listedLeaves = 0;
    std::vector<StreamBlock> all;   ///< every block, in the grid's order (StreamBlock::id is its index)
    std::vector<uint32_t> order;    ///< the blocks in the frustum, front to back (dMin, then id)
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    std::vector<uint32_t> onVoxels;
    std::vector<uint8_t> inside;
    std::vector<uint64_t> keys, scratch;
};

/// @brief The stream's voxel buffers. A caller rendering many images keeps them from one render
/// to the next (render/hybrid.h, ForwardBuffers): they grow, never shrink, and are emptied or
/// rewritten before use, so a render never depends on what they held.
struct StreamBuffers {
    VoxelBatch pending, pendingNext;
    std::vector<VoxelBatch> extracted;
    StreamBlocks blocks;     ///< the block list and its order
    LodMomentCache moments;  ///< only with StreamOptions::keepMoments
};

class VoxelStream {
public:
    /// @brief Streams @p volume for @p camera; @p table classifies values.
    /// @throw Error when the grid is too large to stream (more than 2^32 active voxels).
    /// @p shader: shades each voxel after classification (nullptr: unshaded; docs/shading.md).
    /// @p emission: adds each voxel's emission after shading (nullptr: none; docs/emission.md).
    /// @param buffers where the pending and extracted voxels live (kept by the caller across
    /// renders, so their pages are faulted in once; StreamBuffers); null: its own.
    VoxelStream(const Volume& volume, const Camera& camera, const ClassificationTable& table,
                const StreamOptions& options = {}, const VoxelShader* shader = nullptr,
                const EmissionSource* emission = nullptr, StreamBuffers* buffers = nullptr);

    /// @brief Fills @p batch with the next window front to back; false when the stream is done.
    /// @param hidden optional: returns true for a block whose screen rectangle (pixels,
    /// x0, y0, x1, y1 inclusive) is entirely behind opaque pixels, so it can be skipped.
    /// @param partlyHidden optional, with @p hidden: true when some pixel of the rectangle is
    /// behind opaque pixels; a leaf drawn voxel by voxel for which it holds is tested octant by
    /// octant (4³ voxels each) with @p hidden, and the hidden octants are not extracted.
    bool next(StreamWindow& window, const std::function<bool(int, int, int, int)>& hidden = {},
              const std::function<bool(int, int, int, int)>& partlyHidden = {});
    /// @brief As above, the window's records copied into @p batch (StreamWindow::copyTo).
    bool next(VoxelBatch& batch, const std::function<bool(int, int, int, int)>& hidden = {},
              const std::function<bool(int, int, int, int)>& partlyHidden = {});

    uint64_t culledVoxels() const { return counts_.frustum + counts_.occluded; }  ///< voxels in culled blocks
    const StreamCounts& counts() const { return counts_; }
    uint64_t windows() const { return windows_; }        ///< windows released so far
    size_t largestWindow() const { return largest_; }    ///< most voxels in one window so far
    double slabLength() const { return slabLength_; }    ///< world length of one slab
    /// Fraction of the visible blocks streamed so far (for progress reports).
    double progress() const { return order_.empty() ? 1.0 : double(nextBlock_) / double(order_.size()); }

private:
    using Block = StreamBlock;
    /// The block list (listBlocks, unless the kept list is this tree's), then frameBlocks.
    void collectBlocks();
    /// Lists the grid's blocks: its leaves with active voxels, then its active tiles' 8³ blocks.
    void listBlocks(uint64_t leafCount);
    /// What the view decides of each block: its distance bounds, the frustum test, the level of
    /// detail; then the blocks in the frustum, front to back (order_).
    void frameBlocks();
    bool visible(const Block& b) const;
    void screenRect(const Block& b, int& x0, int& y0, int& x1, int& y1) const;
    /// The pixels the deposits of the voxels [origin, origin + dim)³ can reach: the box of their
    /// centres, widened by the kernel radius unless @p points (then the centres' box alone: a
    /// point, voxel or aggregate, is centred inside it and reaches ≤ kPointMaxRadiusPx), plus the
    /// screen margin.
    void screenRect(const openvdb::Coord& origin, int dim, bool points, int& x0, int& y0, int& x1, int& y1) const;
    /// The octants of leaf @p b not hidden, as value-mask words (@p visible); adds the active
    /// voxels of the hidden ones to @p occluded. False (nothing set) when no octant is hidden.
    bool visibleOctants(const Block& b, const std::function<bool(int, int, int, int)>& hidden,
                        std::array<uint64_t, 8>& visible, uint64_t& occluded) const;
    void lodLevel(Block& b) const;  // sets b.lodLevel, b.lodFine and b.pointsOnly
    static size_t recordsOf(const Block& b);  // about how many records b's extraction gives
    /// counts: aggregates only. @p visible: the leaf's voxels to extract, as value-mask words
    /// (a level-0 leaf block only); null: all.
    void extract(const Block& b, VoxelBatch& out, StreamCounts& counts, const uint64_t* visible = nullptr) const;
    void extractVoxels(const Block& b, const float* coarse, VoxelBatch& out, const uint64_t* visible = nullptr) const;
    /// The moments of @p b's cells at @p level: its kept slots (packed), or @p scratch (room for 64
    /// cells) filled and marked in place.
    PackedCells cellMoments(const Block& b, int level, CellMoments* scratch) const;
    bool keepsLevel(const Block& b, int level) const;  // this level's cells of b are kept between renders
    bool momentsKept(const Block& b) const;  // drawn at one level from kept cells (reads no voxel)
    void computeCellMoments(const Block& b, int level, CellMoments* acc) const;  // writes all of b's cells at level
    bool shadeWholeLeaf(const Block& b, LeafFactors& factors) const;  // a shaded leaf's factors at once
    void prepareMomentCache(size_t blocks);  // keys (or empties) the kept moments for this grid and table
    void emitCells(const Block& b, int level, PackedCells acc, const float* coarse, bool fineSide,
                   VoxelBatch& out, StreamCounts& counts) const;
    template <typename Keep, typename Fn> void forEachActive(const Block& b, Keep&& keep, Fn&& fn) const;
    void adaptWindow(size_t released);  // the next window's slab count from this one's size
    /// The pending records and the window's @p blocks new ones under @p limit → @p window (read where
    /// they are, moved to the front of their source where it is taken in part), the rest → pending,
    /// in the same order.
    void release(size_t blocks, float limit, StreamWindow& window);

    const Volume& volume_;
    const Camera& camera_;
    const ClassificationTable& table_;
    StreamOptions options_;
    const VoxelShader* shader_;
    const EmissionSource* emission_;
    double slabLength_;
    std::unique_ptr<StreamBuffers> own_;  // the buffers, unless the caller keeps them
    StreamBlocks& blockList_;       // the buffers' block list (blocks_ and order_ are its)
    std::vector<Block>& blocks_;    // every block, in the grid's order (Block::id is its index)
    std::vector<uint32_t>& order_;  // the blocks in the frustum, front to back (dMin, then id)
    const Block& block(size_t k) const { return blocks_[order_[k]]; }  // the k-th in order_
    size_t nextBlock_ = 0;
    VoxelBatch& pending_;         // voxels of activated blocks not yet released
    VoxelBatch& pendingNext_;     // the pending voxels a window keeps (swapped with pending_)
    std::vector<VoxelBatch>& extracted_;  // per chunk of kExtractChunk activated blocks of the window (reused)
    std::vector<std::pair<size_t, size_t>> blockRecords_;  // per activated block: its records in its chunk's buffer
    std::vector<char> skipped_;          // per activated block: hidden behind opaque tiles
    std::vector<StreamCounts> blockCounts_;  // per activated block: its aggregates
    LodMomentCache* moments_ = nullptr;  // kept moments (StreamOptions::keepMoments), or null
    int64_t nextSlab_ = 0;
    size_t records_ = 0;          // about how many records the blocks give (recordsOf), once known
    int slabsPerWindow_ = 8;      // adapted between 1 and options_.slabsPerWindow (maxWindowVoxels)
    bool pendingSwapped_ = false;  // pending_ and pendingNext_ hold each other's buffers (release)
    glm::dmat4 indexToView_{1.0};  // index space → view space (eye at origin, +z forward)
    // The voxel's shape in world units (volume/grid.h: any affine map): the largest semi-axis
    // per index unit (the kernel's bounding sphere is R·this) and the half-diagonal of a block's
    // voxel centres (bounds the block's distance range). For cubic voxels h and 3.5√3·h.
    double largestAxis_ = 1.0;
    double blockHalfDiagonal_ = 0.0;
    StreamCounts counts_;
    uint64_t windows_ = 0;
    size_t largest_ = 0;
};

}  // namespace vdbsplat
