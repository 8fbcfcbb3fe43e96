// volume/stream.cpp — depth-ordered block streaming (see stream.h, DESIGN §5).
#include "volume/stream.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdlib>
#include <array>
#include <bit>
#include <cmath>
#include <optional>
#include <type_traits>

#include "footprint/ellipsoid.h"
#include "footprint/kernel.h"
#include "pointfilter/point_filter.h"
#include "shading/shading_field.h"
#include "volume/cell_records.h"
#include "volume/leaf_extract.h"
#include "volume/leaf_moments.h"
#include "util/error.h"
#include "util/radix_sort.h"
#include "util/fnv1a.h"
#include "volume/emission.h"

namespace vdbsplat {

namespace {
constexpr int kBlockDim = 8;  // OpenVDB leaf side; active tiles are split into blocks of this side
constexpr size_t kMaxWindowBlocks = 512;  // a window grows past its slabs up to this many blocks (recordsOf)
constexpr size_t kExtractChunk = 16;      // blocks extracted into one buffer, in order (VoxelStream::next)
constexpr uint64_t kMaxActiveVoxels = uint64_t(1) << 32;
}  // namespace

void VoxelBatch::resize(size_t n) {
    resizeWritten(viewPos, n), resizeWritten(distance, n), resizeWritten(sigma, n), resizeWritten(color, n);
    resizeWritten(spread, n), resizeWritten(depthSpread, withDepthSpread ? n : 0), resizeWritten(members, n);
}

void VoxelBatch::reserve(size_t n, bool depthSpreads) {
    viewPos.reserve(n), distance.reserve(n), sigma.reserve(n), color.reserve(n), spread.reserve(n), members.reserve(n);
    if (depthSpreads) depthSpread.reserve(n);
}

void VoxelBatch::clear() {
    viewPos.clear();
    distance.clear();
    sigma.clear();
    color.clear();
    spread.clear();
    depthSpread.clear();
    members.clear();
}

VoxelStream::VoxelStream(const Volume& volume, const Camera& camera, const ClassificationTable& table,
                         const StreamOptions& options, const VoxelShader* shader, const EmissionSource* emission,
                         StreamBuffers* buffers)
    : volume_(volume), camera_(camera), table_(table), options_(options), shader_(shader), emission_(emission),
      slabLength_(options.slabThickness * volume.voxelSize), own_(buffers ? nullptr : std::make_unique<StreamBuffers>()),
      blockList_(buffers ? buffers->blocks : own_->blocks), blocks_(blockList_.all), order_(blockList_.order),
      pending_(buffers ? buffers->pending : own_->pending), pendingNext_(buffers ? buffers->pendingNext : own_->pendingNext),
      extracted_(buffers ? buffers->extracted : own_->extracted), slabsPerWindow_(std::max(1, options.slabsPerWindow)) {
    pending_.clear();  // kept buffers: what a stopped render left
    if (volume.activeVoxels > kMaxActiveVoxels)
        throw Error(volume.file + ": grid '" + volume.name + "' has " + std::to_string(volume.activeVoxels) +
                    " active voxels, more than the 2^32 vdbsplat streams");
    // view = R·(world − eye) with rows right, up, forward.
    glm::dmat4 worldToView(1.0);
    const glm::dvec3 r = camera_.right(), u = camera_.up(), f = camera_.forward();
    for (int c = 0; c < 3; ++c) {
        worldToView[c][0] = r[c];
        worldToView[c][1] = u[c];
        worldToView[c][2] = f[c];
    }
    worldToView[3] = glm::dvec4(-glm::dot(r, camera_.eye()), -glm::dot(u, camera_.eye()), -glm::dot(f, camera_.eye()), 1.0);
    indexToView_ = worldToView * volume_.indexToWorld;
    // Any affine voxel (volume/grid.h): the block's half-diagonal is the longest of A·(±1, ±1, ±1)
    // times 3.5, the kernel's reach R times A's largest singular value. Cubes: 3.5√3·h and R·h.
    const glm::dmat3 A(volume_.indexToWorld);
    double diagonal = 0.0;
    for (int s = 0; s < 4; ++s)
        diagonal = std::max(diagonal, glm::length(A * glm::dvec3(1.0, s & 1 ? -1.0 : 1.0, s & 2 ? -1.0 : 1.0)));
    blockHalfDiagonal_ = 0.5 * (kBlockDim - 1) * (volume_.isotropic ? std::sqrt(3.0) * volume_.voxelSize : diagonal);
    largestAxis_ = volume_.largestAxis();
    if (options_.keepMoments && !shader_ && !emission_ && table_.entries()) moments_ = &(buffers ? buffers->moments : own_->moments);
    collectBlocks();
}

void VoxelStream::collectBlocks() {
    const auto& tree = *volume_.tree;
    std::vector<Block>& all = blocks_;  // in the grid's order: a block's id is its place here
    const uint64_t leafCount = tree.leafCount();
    const bool listed = !all.empty() && blockList_.listedTree.lock() == volume_.tree &&
                        blockList_.listedVoxels == volume_.activeVoxels && blockList_.listedLeaves == leafCount;
    if (!listed) listBlocks(leafCount);
    if (moments_) prepareMomentCache(all.size());
    frameBlocks();
}

void VoxelStream::listBlocks(uint64_t leafCount) {
    const auto& tree = *volume_.tree;
    blockList_.listedTree.reset();  // until the list is whole
    // The leaves from the internal nodes' tables (the leaf iterator's order), their voxel counts in
    // parallel: each count reads a leaf's mask for the first time since the load, and the iterator
    // walked them one dependent miss after another (0.5 ms of the far Engine's 10).
    std::vector<const openvdb::FloatTree::LeafNodeType*>& leaves = blockList_.leaves;
    leaves.clear();
    leaves.reserve(leafCount);
    tree.getNodes(leaves);
    std::vector<uint32_t>& onVoxels = blockList_.onVoxels;
    onVoxels.resize(leaves.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) onVoxels[i] = uint32_t(leaves[i]->onVoxelCount());
    });
    std::vector<Block>& all = blocks_;
    all.clear();
    all.reserve(leaves.size());
    for (size_t i = 0; i < leaves.size(); ++i)
        if (onVoxels[i] != 0)
            all.push_back({leaves[i]->origin(), kBlockDim, leaves[i], 0.f, 0.f, 0.f, onVoxels[i], 0, 0.f, uint32_t(all.size())});
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
                                   uint32_t(kBlockDim * kBlockDim * kBlockDim), 0, 0.f, uint32_t(all.size())});
    }
    blockList_.listedTree = volume_.tree;
    blockList_.listedVoxels = volume_.activeVoxels, blockList_.listedLeaves = leafCount;
}

void VoxelStream::frameBlocks() {
    std::vector<Block>& all = blocks_;
    // Distance bounds of voxel centres (the block's bounding sphere around its centre), the frustum
    // test and the level of detail, block by block in parallel (each writes only its own block).
    const double halfDiagonal = blockHalfDiagonal_;
    std::vector<uint8_t>& inside = blockList_.inside;
    inside.assign(all.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, all.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            Block& b = all[i];
            const glm::dvec3 centreIdx = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + 0.5 * (b.dim - 1);
            const glm::dvec3 centre(volume_.indexToWorld * glm::dvec4(centreIdx, 1.0));
            const double dist = glm::length(centre - camera_.eye());
            b.dMin = float(std::max(0.0, dist - halfDiagonal));
            b.dMax = float(dist + halfDiagonal);
            inside[i] = visible(b);
            if (inside[i]) lodLevel(b);
            else b.lodLevel = 0, b.lodFine = 0.f, b.pointsOnly = false;  // a kept list's last view's
        }
    });
    // Front to back by nearest distance, ties in the grid's order (the blocks' ids): one total
    // order, whatever the thread count. A radix sort (util/radix_sort.h) of 64-bit keys (dMin's
    // bits, ≥ 0 so ordered as integers, then the id): the comparison sort of the blocks, its branches unpredictable,
    // took 0.3–0.5 ms of the far Engine's 5 (4 448 blocks).
    std::vector<uint64_t>& keys = blockList_.keys;
    keys.clear();
    keys.reserve(all.size());
    for (size_t i = 0; i < all.size(); ++i) {
        if (inside[i]) keys.push_back(uint64_t(std::bit_cast<uint32_t>(all[i].dMin)) << 32 | all[i].id);
        else counts_.frustum += all[i].voxels;
    }
    std::vector<uint64_t>& scratch = blockList_.scratch;
    scratch.resize(keys.size());
    const uint64_t* sorted = radixSortBits(keys.data(), scratch.data(), keys.size(), 0, 64);
    // The order as indices: the blocks stay where they are (a sorted copy of them was a fresh
    // 48 bytes a block, 52 page faults for the Engine's 4 448, 0.15 ms of a far render's 5).
    order_.resize(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) order_[i] = uint32_t(sorted[i]);
}

bool VoxelStream::visible(const Block& b) const {
    const glm::dvec3 centreIdx = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + 0.5 * (b.dim - 1);
    const glm::dvec3 c = camera_.toView(glm::dvec3(volume_.indexToWorld * glm::dvec4(centreIdx, 1.0)));
    const double radius = blockHalfDiagonal_ + Kernel::kRadius * largestAxis_;
    if (c.z < -radius) return false;  // entirely behind the eye
    // Side planes of the frustum widened by the screen margin, x = z·t for the slopes t of the
    // image's edges (the principal point need not be centred: a cropped camera).
    const double m = options_.screenMargin, f = camera_.focal();
    const PixelCoord p = camera_.principal();
    const double left = (p.x + m) / f, right = (camera_.width() - p.x + m) / f;  // x ∈ [−z·left, z·right]
    const double top = (p.y + m) / f, bottom = (camera_.height() - p.y + m) / f;  // y ∈ [−z·bottom, z·top]
    const auto outside = [&](double u, double t) { return (u - t * c.z) / std::sqrt(1.0 + t * t) > radius; };
    return !outside(c.x, right) && !outside(-c.x, left) && !outside(c.y, top) && !outside(-c.y, bottom);
}

void VoxelStream::screenRect(const Block& b, int& x0, int& y0, int& x1, int& y1) const {
    screenRect(b.origin, b.dim, b.pointsOnly, x0, y0, x1, y1);
}

void VoxelStream::screenRect(const openvdb::Coord& origin, int dim, bool points, int& x0, int& y0, int& x1, int& y1) const {
    // Project the corners of the box of voxel centres [origin, origin + dim)³, widened by the
    // kernel radius for splats; the margin covers the prefilter and a point's filter (the box of a
    // point's pixels, centres within kPointMaxRadiusPx of its own, lies within the margin of its
    // centre: a voxel's, or an aggregate's σ-weighted centroid of voxel centres). Any corner at
    // or behind the eye plane: the whole screen. The map is affine: one corner through it, then
    // the box's three edges as offsets.
    const double r = points ? 0.0 : Kernel::kRadius + 0.5, side = double(dim - 1) + 2.0 * r;
    const glm::dvec3 low(indexToView_ * glm::dvec4(origin.x() - r, origin.y() - r, origin.z() - r, 1.0));
    const glm::dmat3 edges = glm::dmat3(indexToView_) * side;
    double lox = 1e300, loy = 1e300, hix = -1e300, hiy = -1e300;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 v = low + (corner & 1 ? edges[0] : glm::dvec3(0.0)) + (corner & 2 ? edges[1] : glm::dvec3(0.0)) +
                             (corner & 4 ? edges[2] : glm::dvec3(0.0));
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
    const double m = points ? std::max(options_.screenMargin, kPointMaxRadiusPx + 0.5) : options_.screenMargin;
    x0 = int(std::clamp(std::floor(lox - m), 0.0, double(camera_.width() - 1)));
    x1 = int(std::clamp(std::ceil(hix + m), 0.0, double(camera_.width() - 1)));
    y0 = int(std::clamp(std::floor(loy - m), 0.0, double(camera_.height() - 1)));
    y1 = int(std::clamp(std::ceil(hiy + m), 0.0, double(camera_.height() - 1)));
}

// The 4³ octant (i, j, k) of a leaf holds the voxels x ∈ [4i, 4i + 4), y ∈ [4j, 4j + 4),
// z ∈ [4k, 4k + 4): in mask word x (bit y·8 + z), these bits.
namespace {
constexpr uint64_t octantBits(int j, int k) {
    uint64_t bits = 0;
    for (int y = 4 * j; y < 4 * j + 4; ++y) bits |= uint64_t(0xf) << (4 * k) << (8 * y);
    return bits;
}
}  // namespace

bool VoxelStream::visibleOctants(const Block& b, const std::function<bool(int, int, int, int)>& hidden,
                                 std::array<uint64_t, 8>& visible, uint64_t& occluded) const {
    visible.fill(0);
    bool any = false;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) {
                int x0, y0, x1, y1;
                screenRect(b.origin.offsetBy(4 * i, 4 * j, 4 * k), 4, b.pointsOnly, x0, y0, x1, y1);
                if (hidden(x0, y0, x1, y1)) {
                    any = true;
                    continue;
                }
                for (int x = 4 * i; x < 4 * i + 4; ++x) visible[size_t(x)] |= octantBits(j, k);
            }
    if (!any) return false;
    for (int x = 0; x < 8; ++x)
        occluded += uint64_t(std::popcount(b.leaf->getValueMask().template getWord<uint64_t>(openvdb::Index(x)) & ~visible[size_t(x)]));
    return true;
}

void VoxelStream::lodLevel(Block& b) const {
    b.lodLevel = 0, b.lodFine = 0.f, b.pointsOnly = options_.pointBelowPx == INFINITY;  // point mode: all points
    if (!(options_.pointBelowPx > 0.0)) return;
    const glm::dvec3 centreIdx = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + 0.5 * (b.dim - 1);
    const glm::dvec3 c(indexToView_ * glm::dvec4(centreIdx, 1.0));
    const double zNear = c.z - blockHalfDiagonal_;  // nearest voxel centre's depth, bounded
    if (!(zNear > 0.0)) return;
    // The block's largest projected voxel spacing (the longest voxel axis: as the projection decides).
    const double spacingPx = largestAxis_ * camera_.focal() / zNear;
    if (!(spacingPx < options_.pointBelowPx)) return;     // some voxel may be a splat
    b.pointsOnly = true;
    if (!(options_.lodCellPx > 0.0)) return;
    // The admissible level ℓ, continuous: a cell of n = 2^ℓ voxels per side projects to n·s px (at
    // most lodCellPx) and, uniform, would add the spread s²·(n² − 1)/12 px² per axis (s the projected
    // spacing), at most kLodMaxSpreadRatio of the points' own filter variance.
    const double filter = pointFilterVariance(spacingPx, options_.pointPrefilterVariance);
    const double bySize = std::log2(options_.lodCellPx / spacingPx);
    const double bySpread = 0.5 * std::log2(1.0 + 12.0 * kLodMaxSpreadRatio * filter / (spacingPx * spacingPx));
    double ell = std::min(bySize, bySpread);
    // The second cap (StreamOptions::lodCoarseCellPx): past the first passage's start, the level
    // the coarser cap admits; the first passage itself keeps lodCellPx, whose losses a larger cap
    // would bring there (session 33's sweep).
    if (options_.lodCoarseCellPx > options_.lodCellPx && options_.lodBlend != LodBlend::On && ell >= 1.0)
        ell = std::max(ell, std::min(std::log2(options_.lodCoarseCellPx / spacingPx), bySpread));
    // The level switches at once where it becomes admissible: everywhere (Off), or in the first
    // passage (Still: from ℓ = 1 the block is 2³ cells, which meets the blended rule at ℓ = 1.75).
    const bool switching = options_.lodBlend == LodBlend::Off ||
                           (options_.lodBlend == LodBlend::Still && ell < kLodPassage[0].second);
    if (switching) {
        if (ell >= 1.0) b.lodLevel = int(std::min(std::floor(ell), 3.0));
        return;
    }
    // Blended: the block passes from level k − 1 to level k while ℓ crosses passage k (kLodPassage):
    // voxels → 2³ over ℓ ∈ [1, 1.75) (2³ cells never come in before they are admissible: coarser
    // cells there flicker more), 2³ → 4³ over [1.75, 2) and 4³ → 8³ over [2.25, 3) (each ends
    // where the switching rule switches, so a block is never drawn finer than by that rule past
    // the first passage: its cost stays the switching rule's, plus the lighter level's records).
    // x = k + progress inside passage k; k between passages.
    double x = 1.0;
    for (int k = 1; k <= 3; ++k) {
        const auto [begin, end] = kLodPassage[k - 1];
        if (ell >= end) x = double(k + 1);
        else if (ell >= begin) x = double(k) + (ell - begin) / (end - begin);
    }
    if (!(ell > kLodPassage[0].first)) return;  // all voxels (also for a NaN ℓ)
    const double level = std::floor(x), progress = x - level;
    if (progress == 0.0) {  // between passages: all at level x − 1
        b.lodLevel = int(level) - 1;
        return;
    }
    b.lodLevel = int(level);
    b.lodFine = float(1.0 - progress);
}

namespace {
/// A voxel's classification as every stream path computes it: the baked table's, then shaded
/// (VoxelShader, the same factors the reference reads) when shading is on, then the emission
/// grid's term added (after shading: emitted light is not lit; docs/emission.md). One per block:
/// it holds the tree accessors, and blocks run on any thread. A shaded leaf's factors are found
/// for the whole leaf at once (@p vectorShading, VoxelShader::shadeLeaf: 8 voxels a vector, the
/// same factors), voxel by voxel otherwise.
class VoxelClassifier {
public:
    VoxelClassifier(const Volume& volume, const ClassificationTable& table, const VoxelShader* shader,
                    const EmissionSource* emission, const openvdb::FloatTree::LeafNodeType* leaf, bool vectorShading)
        : table_(table), shader_(shader), emission_(emission) {
        if (shader_) {
            shaderAcc_.emplace(*volume.tree);
            leafShaded_ = leaf && vectorShading && shader_->shadeLeaf(*shaderAcc_, *leaf, factors_);
        }
        if (emission_) emissionAcc_.emplace(emission_->accessor());
    }
    Classified operator()(const openvdb::FloatTree::LeafNodeType* leaf, openvdb::Index n, const openvdb::Coord& ijk,
                          float value) {
        Classified cls = table_(value);
        if (shader_ && cls.sigma > 0.f)
            cls = applyShading(cls, leafShaded_ ? openvdb::Vec3f(factors_.diffuse[n], factors_.specular[n], factors_.opacity[n])
                                                : shader_->shadeDrawn(*shaderAcc_, leaf, n, ijk));
        return emission_ ? applyEmission(cls, emission_->at(*emissionAcc_, ijk)) : cls;
    }

private:
    const ClassificationTable& table_;
    const VoxelShader* shader_;
    const EmissionSource* emission_;
    std::optional<VoxelShader::Accessor> shaderAcc_;
    std::optional<EmissionSource::Accessor> emissionAcc_;
    bool leafShaded_ = false;
    LeafFactors factors_;  // when leafShaded_: the block's leaf's factors, by voxel offset n
};
}  // namespace

/// Calls fn(local index (0..dim−1 per axis), classification) for every active voxel of the
/// block that keep(x, y, z) admits (the others are not classified): the table's, then shaded
/// (VoxelShader, the same factors the reference reads) when shading is on. Shading here, in the
/// parallel extraction, costs only the voxels drawn.
template <typename Keep, typename Fn>
void VoxelStream::forEachActive(const Block& b, Keep&& keep, Fn&& fn) const {
    VoxelClassifier classifyAt(volume_, table_, shader_, emission_, b.leaf, options_.vectorShading);  // per block: blocks run on any thread
    const auto classify = [&](openvdb::Index n, float value) {
        return classifyAt(b.leaf, n, b.origin.offsetBy(int(n >> 6), int((n >> 3) & 7), int(n & 7)), value);
    };
    const auto visit = [&](openvdb::Index n, float value) {
        const int x = int(n >> 6), y = int((n >> 3) & 7), z = int(n & 7);
        if (keep(x, y, z)) fn(x, y, z, classify(n, value));
    };
    if (b.leaf) {
        const float* values = b.leaf->buffer().data();
        if (b.voxels == openvdb::FloatTree::LeafNodeType::SIZE) {  // dense leaf: no mask walk
            for (openvdb::Index n = 0; n < openvdb::FloatTree::LeafNodeType::SIZE; ++n) visit(n, values[n]);
            return;
        }
        for (auto it = b.leaf->getValueMask().beginOn(); it; ++it) visit(it.pos(), values[it.pos()]);  // n = x·64 + y·8 + z
    } else {
        for (openvdb::Index n = 0; n < openvdb::FloatTree::LeafNodeType::SIZE; ++n) visit(n, b.tileValue);
    }
}

namespace {
/// A cell's own place in a block's blend, in [0, 1): a hash of its global cell coordinates and
/// level (splitmix64's finaliser), so it does not depend on the camera, the block order or the thread.
float cellRank(const openvdb::Coord& cell, int level) {
    uint64_t h = (uint64_t(uint32_t(cell.x())) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(uint32_t(cell.y())) * 0xC2B2AE3D27D4EB4Full) ^
                 (uint64_t(uint32_t(cell.z())) * 0x165667B19E3779F9ull) ^ uint64_t(level);
    h ^= h >> 30, h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 27, h *= 0x94D049BB133111EBull;
    h ^= h >> 31;
    return float(h >> 40) * (1.f / float(1 << 24));
}
}  // namespace

namespace {
/// The @p count cells at @p cells, those with mass (Σσ > 0 or a voxel counted) marked, in place.
PackedCells cellsWithMass(const CellMoments* cells, int count) {
    uint64_t mask = 0;
    for (int i = 0; i < count; ++i)
        if (cells[i].m > 0.f || cells[i].n != 0) mask |= uint64_t(1) << i;
    return {cells, mask, false};
}

/// Cell @p i of a block's (8 >> @p level)³ cells at (cx·c + cy)·c + cz, as (cx, cy, cz): by shifts
/// (three integer divisions per cell cost a few per cent of a warm far render, session 28).
glm::ivec3 cellOf(int i, int level) {
    static_assert(kBlockDim == 8, "blocks of 8³ voxels: (8 >> level) cells a side, 3 − level bits");
    const int bits = 3 - level, mask = (1 << bits) - 1;
    return {i >> (2 * bits), (i >> bits) & mask, i & mask};
}

/// Room for a block's cells at any level (≤ (8/2)³), left unzeroed (CellMoments zeroes itself).
struct MomentScratch {
    union {
        CellMoments cells[64];
    };
    MomentScratch() {}
};
}  // namespace

// A block between two levels (lodFine > 0) passes from level k − 1 to level k cell by cell: each
// cell of level k has a coarse weight w_c that rises from 0 to 1 as the block's weight
// t = 1 − lodFine does, over its own stretch of t (voxels → 2³: a fraction lodVoxelRamp of it,
// placed by the cell's rank; between aggregates all of it), and is drawn at level k with its
// optical depth scaled by w_c and as its level-(k − 1) children (or voxels) scaled by 1 − w_c.
// Optical depth is linear in σ, so each cell keeps its energy exactly; the weights follow the
// camera continuously, so nothing pops; and only the cells inside their stretch are drawn twice.
// The level with the larger weight carries the voxel counts (members), the other 0: each voxel
// is counted once.
void VoxelStream::extract(const Block& b, VoxelBatch& out, StreamCounts& counts, const uint64_t* visible) const {
    if (b.lodLevel == 0) return extractVoxels(b, nullptr, out, visible);
    MomentScratch scratch;  // not zeroed: computeCellMoments writes every cell
    if (!(b.lodFine > 0.f)) return emitCells(b, b.lodLevel, cellMoments(b, b.lodLevel, scratch.cells), nullptr, false, out, counts);
    const int k = b.lodLevel, parents = kBlockDim >> k;
    // From the voxels, cell by cell (drawing a block twice would cost its voxels again); between
    // aggregates, every cell at once (the finer level costs 8× fewer records than the voxels).
    const double t = 1.0 - double(b.lodFine), ramp = k == 1 ? std::clamp(options_.lodVoxelRamp, 1e-3, 1.0) : 1.0;
    std::array<float, 64> coarse{};  // per level-k cell: its weight w_c at level k (1 − w_c at level k − 1)
    for (int cx = 0; cx < parents; ++cx)
        for (int cy = 0; cy < parents; ++cy)
            for (int cz = 0; cz < parents; ++cz) {
                const size_t i = size_t((cx * parents + cy) * parents + cz);
                const openvdb::Coord cell((b.origin.x() >> k) + cx, (b.origin.y() >> k) + cy, (b.origin.z() >> k) + cz);
                const double w = ramp >= 1.0 ? t : std::clamp((t - double(cellRank(cell, k)) * (1.0 - ramp)) / ramp, 0.0, 1.0);
                coarse[i] = float(w);
            }
    if (k == 1) {
        extractVoxels(b, coarse.data(), out);
        return emitCells(b, 1, cellMoments(b, 1, scratch.cells), coarse.data(), false, out, counts);
    }
    // Level k − 1's moments, emitted for the cells' fine weights, then level k's from them (each
    // parent the sum of its 8 children, moved from the child's centre to the parent's: d + o).
    const int level = k - 1, cells = kBlockDim >> level;
    const float childSide = float(1 << level);
    const PackedCells fine = cellMoments(b, level, scratch.cells);
    std::array<float, 64> parentWeight{};
    for (int cx = 0; cx < cells; ++cx)
        for (int cy = 0; cy < cells; ++cy)
            for (int cz = 0; cz < cells; ++cz)
                parentWeight[size_t((cx * cells + cy) * cells + cz)] =
                    coarse[size_t(((cx >> 1) * parents + (cy >> 1)) * parents + (cz >> 1))];
    emitCells(b, level, fine, parentWeight.data(), true, out, counts);
    MomentScratch parentsScratch;  // only the parents³ cells used are zeroed (8 or 1: not all 64, 3.8 KB)
    CellMoments* up = parentsScratch.cells;
    std::fill_n(up, parents * parents * parents, CellMoments{});
    int j = 0;
    for (uint64_t bits = fine.mask; bits != 0; bits &= bits - 1, ++j) {
        const int i = std::countr_zero(bits);
        const auto [cx, cy, cz] = cellOf(i, level);
        const CellMoments& a = fine.at(i, j);
        CellMoments& p = up[size_t(((cx >> 1) * parents + (cy >> 1)) * parents + (cz >> 1))];
        const glm::vec3 o = (glm::vec3(float(cx & 1), float(cy & 1), float(cz & 1)) - 0.5f) * childSide;
        p.m += a.m;
        p.emission += a.emission;
        p.first += a.first + a.m * o;
        p.xx += a.xx + 2.f * o.x * a.first.x + a.m * o.x * o.x;
        p.yy += a.yy + 2.f * o.y * a.first.y + a.m * o.y * o.y;
        p.zz += a.zz + 2.f * o.z * a.first.z + a.m * o.z * o.z;
        p.xy += a.xy + o.x * a.first.y + o.y * a.first.x + a.m * o.x * o.y;
        p.xz += a.xz + o.x * a.first.z + o.z * a.first.x + a.m * o.x * o.z;
        p.yz += a.yz + o.y * a.first.z + o.z * a.first.y + a.m * o.y * o.z;
        p.n += a.n;
    }
    emitCells(b, k, cellsWithMass(up, parents * parents * parents), coarse.data(), false, out, counts);
}

// A shaded leaf's factors for all its voxels at once (VoxelShader::shadeLeaf), for the vectorised
// extraction and sums: false where the stream shades voxel by voxel (the oracle, or no 8-float
// vectors).
bool VoxelStream::shadeWholeLeaf(const Block& b, LeafFactors& factors) const {
    if (!shader_ || !b.leaf || !options_.vectorShading) return false;
    VoxelShader::Accessor acc(*volume_.tree);  // per block: blocks run on any thread
    return shader_->shadeLeaf(acc, *b.leaf, factors);
}

// coarse: per level-1 cell (x>>1, y>>1, z>>1) its weight w_c at level 1; the voxels take 1 − w_c
// (none drawn, nor classified, where w_c = 1) and carry the counts where w_c < ½. nullptr: w_c = 0.
void VoxelStream::extractVoxels(const Block& b, const float* coarse, VoxelBatch& out, const uint64_t* visible) const {
    const glm::dvec3 origin(b.origin.x(), b.origin.y(), b.origin.z());
    const auto wc = [&](int x, int y, int z) { return coarse ? coarse[size_t(((x >> 1) * 4 + (y >> 1)) * 4 + (z >> 1))] : 0.f; };
    // Sized for the block's active voxels first (forEachActive visits exactly b.voxels: the
    // leaf's on-voxel count, or all 512 of a dense leaf or a tile), written by index, cut to the
    // voxels kept: no capacity check per array and voxel (the buffers do not initialise what
    // resize adds). By the count, not 512, so a window of sparse blocks stays small (a bound
    // check per voxel here cost the stream 60 %: 32 → 53 ms on the framed Engine).
    const size_t first = out.size();
    out.withDepthSpread = options_.depthSpread;
    // (kLeafRecordSlack: the vector path may store records past its last, cut off below.)
    out.resize(first + std::min<size_t>(b.voxels, openvdb::FloatTree::LeafNodeType::SIZE) + kLeafRecordSlack);
    size_t k = first;
    // A leaf without emission or blend weights (shaded by its factors where shading is on): a
    // vector of rows at a time (volume/leaf_extract.h), the same records as the voxel-by-voxel
    // path below.
    LeafFactors factors;  // a shaded leaf's (VoxelShader::shadeLeaf)
    if (!coarse && b.leaf && !emission_ && options_.vectorExtract && table_.entries() && leafExtractSupported() &&
        (!shader_ || shadeWholeLeaf(b, factors))) {
        const bool dense = b.voxels == openvdb::FloatTree::LeafNodeType::SIZE && !visible;
        std::array<uint64_t, 8> words;
        for (int x = 0; x < 8; ++x)
            words[size_t(x)] = b.leaf->getValueMask().template getWord<uint64_t>(openvdb::Index(x)) & (visible ? visible[x] : ~uint64_t(0));
        const LeafRecords to{out.viewPos.data() + first, out.distance.data() + first, out.sigma.data() + first,
                             out.color.data() + first};
        k += extractLeafVoxels(b.leaf->buffer().data(), dense ? nullptr : words.data(), table_, indexToView_,
                               glm::ivec3(b.origin.x(), b.origin.y(), b.origin.z()), to, shader_ ? &factors : nullptr);
        std::fill(out.spread.begin() + ptrdiff_t(first), out.spread.begin() + ptrdiff_t(k), 0.f);
        if (options_.depthSpread) std::fill(out.depthSpread.begin() + ptrdiff_t(first), out.depthSpread.begin() + ptrdiff_t(k), 0.f);
        std::fill(out.members.begin() + ptrdiff_t(first), out.members.begin() + ptrdiff_t(k), 1u);
        out.resize(k);
        return;
    }
    const auto shown = [&](int x, int y, int z) { return !visible || (visible[x] >> (y * 8 + z) & 1u); };
    forEachActive(b, [&](int x, int y, int z) { return wc(x, y, z) < 1.f && shown(x, y, z); },
                  [&](int x, int y, int z, const Classified& cls) {
        if (!(cls.sigma > 0.f)) return;
        const float c = wc(x, y, z), w = 1.f - c;
        const glm::dvec3 v(indexToView_ * glm::dvec4(origin + glm::dvec3(x, y, z), 1.0));
        out.viewPos[k] = glm::vec3(v);
        out.distance[k] = float(glm::length(v));
        out.sigma[k] = w == 1.f ? cls.sigma : cls.sigma * w;
        out.color[k] = cls.color;
        out.spread[k] = 0.f;
        if (options_.depthSpread) out.depthSpread[k] = 0.f;
        out.members[k] = c < 0.5f ? 1 : 0;
        ++k;
    });
    out.resize(k);
}

/// Calls fn(x, y, sigma, color) for every (x, y) row of the block: the row's 8 voxels along z
/// (OpenVDB's fastest axis, n = x·64 + y·8 + z) classified as forEachActive does, with σ = 0
/// for inactive voxels. Rows without an active voxel are skipped.
namespace {
template <typename Fn>
void forEachRow(const auto& b, const Volume& volume, const ClassificationTable& table, const VoxelShader* shader,
                const EmissionSource* emission, bool vectorShading, Fn&& fn) {
    constexpr int kDim = kBlockDim;
    VoxelClassifier classify(volume, table, shader, emission, b.leaf, vectorShading);
    std::array<float, kDim> sigma;
    std::array<glm::vec3, kDim> color;
    const float* values = b.leaf ? b.leaf->buffer().data() : nullptr;
    const bool dense = !b.leaf || b.voxels == openvdb::FloatTree::LeafNodeType::SIZE;
    for (int x = 0; x < kDim; ++x) {
        const uint64_t word = dense ? ~uint64_t(0) : b.leaf->getValueMask().template getWord<uint64_t>(openvdb::Index(x));
        for (int y = 0; y < kDim; ++y) {
            const unsigned bits = unsigned(word >> (8 * y)) & 0xffu;
            if (bits == 0) continue;
            for (int z = 0; z < kDim; ++z) {
                const openvdb::Index n = openvdb::Index((x << 6) | (y << 3) | z);
                if (!(bits >> z & 1u)) {
                    sigma[size_t(z)] = 0.f, color[size_t(z)] = glm::vec3(0.f);
                    continue;
                }
                const Classified cls = classify(b.leaf, n, b.origin.offsetBy(x, y, z), values ? values[n] : b.tileValue);
                sigma[size_t(z)] = cls.sigma, color[size_t(z)] = cls.color;
            }
            fn(x, y, sigma, color);
        }
    }
}
}  // namespace

// Level of detail (DESIGN §8.2): one record per cell of s = 2^L voxels per side with the cell's
// optical-depth mass m = Σσ_k, colour Σσ_k c_k / m, σ-weighted centroid μ and the projected
// second moment of its voxels about μ. Moments are accumulated about the cell's centre (|offset|
// ≤ 3.5 voxels) so the float sums do not cancel, row by row: along a row of the block (z) the
// offsets dx and dy are constant, so the row's Σσ, Σσ·dz and Σσ·dz² give every moment
// (Σσ·dx·dz = dx·Σσ·dz, Σσ·dx² = dx²·Σσ, ...): three sums per voxel instead of ten.
// The grid (its file, name, tree, voxel count and transform) and the baked table (its entries,
// linear pieces and index map): what a block's moments depend on. A different grid or transfer function empties
// the kept slots.
void VoxelStream::prepareMomentCache(size_t blocks) {
    LodMomentCache& cache = *moments_;
    uint64_t key = fnv1a64(volume_.file.data(), volume_.file.size());
    key = fnv1a64(volume_.name.data(), volume_.name.size(), key);
    const uintptr_t tree = reinterpret_cast<uintptr_t>(&*volume_.tree);
    const uint64_t counts[2] = {volume_.activeVoxels, blocks};
    key = fnv1a64(&tree, sizeof tree, key);
    key = fnv1a64(counts, sizeof counts, key);
    key = fnv1a64(&volume_.indexToWorld, sizeof volume_.indexToWorld, key);
    key = fnv1a64Words(table_.entries(), sizeof(Classified) * ClassificationTable::kSize, key);
    const float map[2] = {table_.scale(), table_.offset()};
    key = fnv1a64(map, sizeof map, key);
    const LinearPieces& pieces = table_.pieces();  // what classifies, where it has pieces (not its padding)
    key = fnv1a64(&pieces.count, sizeof pieces.count, key);
    key = fnv1a64(pieces.knot, sizeof pieces.knot, key);
    key = fnv1a64(pieces.value, sizeof pieces.value, key);
    key = fnv1a64(pieces.slope, sizeof pieces.slope, key);
    const uint8_t path = options_.vectorLeafMoments ? 1 : 0;  // the vector and the scalar sums round apart
    key = fnv1a64(&path, sizeof path, key) | 1;  // never 0 (none yet)
    if (cache.key == key && cache.blocks == blocks) return;
    cache.key = key, cache.blocks = blocks;
    // Packed, a level holds at most one cell per active voxel.
    const auto room = [&](size_t cells) { return std::min<size_t>(blocks * cells, volume_.activeVoxels); };
    cache.level1 = room(64) * sizeof(CellMoments) <= LodMomentCache::kLevel1Budget;
    for (int level = 1; level <= 3; ++level) {
        const size_t cells = size_t(kBlockDim >> level) * size_t(kBlockDim >> level) * size_t(kBlockDim >> level);
        const bool kept = level >= 2 || cache.level1;
        std::remove_reference_t<decltype(cache.cells[0])>().swap(cache.cells[level - 1]);  // the old grid's slots go
        cache.cells[level - 1].resize(kept ? room(cells) : 0);
        // Claimed from the front and kept from render to render: huge pages where it is large.
        adviseWritten(cache.cells[level - 1], cache.cells[level - 1].size());
        cache.offset[level - 1].resize(kept ? blocks : 0);
        cache.mask[level - 1].resize(kept ? blocks : 0);
        cache.have[level - 1].assign(kept ? blocks : 0, 0);
        cache.cursor[size_t(level - 1)].store(0, std::memory_order_relaxed);
    }
}

bool VoxelStream::keepsLevel(const Block& b, int level) const {
    return moments_ && level >= 1 && level <= 3 && (level > 1 || moments_->level1) && b.dim == kBlockDim;
}

// A block drawn at one level whose cells are kept: its extraction reads no voxel.
bool VoxelStream::momentsKept(const Block& b) const {
    return !(b.lodFine > 0.f) && keepsLevel(b, b.lodLevel) && moments_->have[size_t(b.lodLevel - 1)][b.id];
}

// Through the kept slots where there are (each block is extracted by one thread, so a slot is
// written by one and read in a later render, after the parallel passes that separate them), read
// in place (they were copied into a zeroed array of 64 cells, 3.6 KB, per block).
PackedCells VoxelStream::cellMoments(const Block& b, int level, CellMoments* scratch) const {
    const int count = (b.dim >> level) * (b.dim >> level) * (b.dim >> level);
    if (!keepsLevel(b, level)) {
        computeCellMoments(b, level, scratch);
        return cellsWithMass(scratch, count);
    }
    LodMomentCache& cache = *moments_;
    const size_t l = size_t(level - 1);
    uint8_t& have = cache.have[l][b.id];
    if (!have) {
        computeCellMoments(b, level, scratch);
        const PackedCells found = cellsWithMass(scratch, count);
        const size_t at = cache.cursor[l].fetch_add(size_t(std::popcount(found.mask)), std::memory_order_relaxed);
        CellMoments* kept = cache.cells[l].data() + at;  // ≤ blocks × cells claimed in all
        for (uint64_t bits = found.mask; bits != 0; bits &= bits - 1) *kept++ = scratch[std::countr_zero(bits)];
        cache.offset[l][b.id] = uint32_t(at), cache.mask[l][b.id] = found.mask;
        have = 1;
    }
    return {cache.cells[l].data() + cache.offset[l][b.id], cache.mask[l][b.id]};
}

void VoxelStream::computeCellMoments(const Block& b, int level, CellMoments* acc) const {
    using Moments = CellMoments;
    const int side = 1 << level, cells = b.dim >> level;
    const float half = 0.5f * float(side - 1);
    // Leaves without emission: the vectorised sums (leaf_moments.h; 2–4× the scalar rows), shaded
    // by the whole leaf's factors where shading is on.
    LeafFactors factors;
    const bool vectorised = level >= 1 && b.leaf && !emission_ && table_.entries() && options_.vectorLeafMoments &&
                            leafMomentsSupported() && (!shader_ || shadeWholeLeaf(b, factors));
    if (vectorised) {
        const bool dense = b.voxels == openvdb::FloatTree::LeafNodeType::SIZE;
        std::array<uint64_t, 8> words;
        for (int x = 0; x < 8; ++x) words[size_t(x)] = b.leaf->getValueMask().template getWord<uint64_t>(openvdb::Index(x));
        leafMoments(b.leaf->buffer().data(), dense ? nullptr : words.data(), table_, level, acc,  // writes every cell
                    shader_ ? &factors : nullptr);
        return;
    }
    std::fill_n(acc, cells * cells * cells, Moments{});  // the row sums below add to zero
    forEachRow(b, volume_, table_, shader_, emission_, options_.vectorShading, [&](int x, int y, const std::array<float, kBlockDim>& sigma, const std::array<glm::vec3, kBlockDim>& color) {
        const float dx = float(x & (side - 1)) - half, dy = float(y & (side - 1)) - half;
        Moments* row = &acc[size_t(((x >> level) * cells + (y >> level)) * cells)];
        for (int cz = 0; cz < cells; ++cz) {
            float s0 = 0.f, sz = 0.f, szz = 0.f;
            glm::vec3 e(0.f);
            uint32_t n = 0;
            for (int k = 0; k < side; ++k) {
                const int z = cz * side + k;
                const float s = sigma[size_t(z)];
                if (!(s > 0.f)) continue;
                const float dz = float(k) - half;
                s0 += s, sz += s * dz, szz += s * dz * dz;
                e += s * color[size_t(z)];
                ++n;
            }
            if (n == 0) continue;
            Moments& a = row[cz];
            a.m += s0;
            a.emission += e;
            a.first += glm::vec3(dx * s0, dy * s0, sz);
            a.xx += dx * dx * s0, a.yy += dy * dy * s0, a.zz += szz;
            a.xy += dx * dy * s0, a.xz += dx * sz, a.yz += dy * sz;
            a.n += n;
        }
    });
}

// coarse: per cell of this level (fineSide: of the level above), the coarse weight w_c; the cell
// takes w_c (fineSide: 1 − w_c; nothing where that is 0) and carries its count where w_c ≥ ½
// (fineSide: < ½). nullptr: weight 1, counted.
void VoxelStream::emitCells(const Block& b, int level, PackedCells acc, const float* coarse, bool fineSide,
                            VoxelBatch& out, StreamCounts& counts) const {
    const int side = 1 << level;
    // In float about the block: its first cell's centre in view space once (double, as every
    // record's position), then per cell offsets of at most 8 voxels through the linear part A. (In
    // double throughout, the cells' conversions and divisions were 12 % of a far render's CPU.)
    const float half = 0.5f * float(side - 1);
    const glm::dvec3 firstCentre = glm::dvec3(b.origin.x(), b.origin.y(), b.origin.z()) + double(half);
    CellFrame frame;
    frame.origin = glm::vec3(indexToView_ * glm::dvec4(firstCentre, 1.0));
    frame.toView = glm::mat3(glm::dmat3(indexToView_));  // linear part: index offsets → view offsets
    frame.focal = float(camera_.focal());
    // A full cell's own second moment, s²·(n² − 1)/12 per index axis (volume/cell_records.h).
    frame.fullMoment = (float(side) * float(side) - 1.f) / 12.f;
    frame.depthSpread = options_.depthSpread;
    // Sized for the cells kept, written by index (it also marks the batch's depth spreads kept or
    // not, as every other record path does); cut to those drawn.
    size_t k = out.size();
    out.withDepthSpread = options_.depthSpread;
    out.resize(k + size_t(std::popcount(acc.mask)));
    // The drawn cells, CellLanes::kMax at a time: their moments in lanes, their records computed
    // together (vectorised: the cells' records were 7 % of a far 1024² render's CPU one by one),
    // then written with their weights and counts.
    CellLanes lanes;
    float weightOf[CellLanes::kMax];
    uint32_t membersOf[CellLanes::kMax];
    int staged = 0;
    const auto flush = [&] {
        if (options_.vectorCells) cellRecords(frame, lanes, staged);
        else cellRecordsScalar(frame, lanes, staged);
        for (int l = 0; l < staged; ++l, ++k) {
            out.viewPos[k] = glm::vec3(lanes.vx[l], lanes.vy[l], lanes.vz[l]);
            out.distance[k] = lanes.distance[l];
            out.sigma[k] = lanes.m[l] * weightOf[l];  // × 1 where not blended: exact
            out.color[k] = glm::vec3(lanes.r[l], lanes.g[l], lanes.b[l]);
            out.spread[k] = lanes.spread[l];
            if (options_.depthSpread) out.depthSpread[k] = lanes.depthSpread[l];
            out.members[k] = membersOf[l];
        }
        staged = 0;
    };
    int j = 0;
    for (uint64_t bits = acc.mask; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        const auto [cx, cy, cz] = cellOf(i, level);
        const CellMoments& a = acc.at(i, j++);
        if (!(a.m > 0.f)) continue;
        const float c = coarse ? coarse[size_t(i)] : 1.f;
        const float weight = fineSide ? 1.f - c : c;
        const bool counted = fineSide ? c < 0.5f : c >= 0.5f;
        if (!(weight > 0.f)) continue;
        const int l = staged++;
        lanes.m[l] = a.m;
        lanes.er[l] = a.emission.x, lanes.eg[l] = a.emission.y, lanes.eb[l] = a.emission.z;
        lanes.fx[l] = a.first.x, lanes.fy[l] = a.first.y, lanes.fz[l] = a.first.z;
        lanes.xx[l] = a.xx, lanes.yy[l] = a.yy, lanes.zz[l] = a.zz, lanes.xy[l] = a.xy, lanes.xz[l] = a.xz, lanes.yz[l] = a.yz;
        lanes.px[l] = float(cx * side), lanes.py[l] = float(cy * side), lanes.pz[l] = float(cz * side);
        weightOf[l] = weight;
        membersOf[l] = counted ? a.n : 0;
        if (counted) ++counts.aggregates, counts.aggregatedVoxels += a.n;
        if (staged == CellLanes::kMax) flush();
    }
    if (staged > 0) flush();
    out.resize(k);
}

// A block's records, about: its voxels, or its cells at a level of detail (both levels' when
// blended). Windows are sized by records, the work downstream: sized by voxels, a far view's
// windows held a few thousand records each, and their fixed costs (a dozen parallel passes
// each) outweighed their work. A window still takes at most kMaxWindowBlocks blocks while it
// grows past its slabs: with the blocks' records in one buffer per kExtractChunk blocks (session
// 14), 128 and 256 blocks measured within noise of 512 on the far views, 4 096 up to 14 % slower.
size_t VoxelStream::recordsOf(const Block& b) {
    if (b.lodLevel == 0) return b.voxels;
    const size_t side = size_t(kBlockDim >> b.lodLevel), cells = side * side * side;
    const size_t atLevel = std::min<size_t>(b.voxels, cells);
    return b.lodFine > 0.f ? std::min<size_t>(b.voxels, 9 * atLevel) : atLevel;  // the finer level: 8× the cells
}

void VoxelStream::adaptWindow(size_t released) {
    const int widest = std::max(1, options_.slabsPerWindow);
    if (released > options_.maxWindowVoxels && slabsPerWindow_ > 1) slabsPerWindow_ /= 2;
    else if (released < options_.maxWindowVoxels / 4 && slabsPerWindow_ < widest)
        slabsPerWindow_ = std::min(widest, 2 * slabsPerWindow_);
}

namespace {
/// A batch's arrays as raw pointers (@p B: VoxelBatch, or const VoxelBatch for a source), taken
/// once per source: a record copied through the vectors would load each vector's data pointer
/// again after every store (the stores may alias them).
template <class B, class F = std::conditional_t<std::is_const_v<B>, const float, float>,
          class V3 = std::conditional_t<std::is_const_v<B>, const glm::vec3, glm::vec3>,
          class U = std::conditional_t<std::is_const_v<B>, const uint32_t, uint32_t>>
struct RecordArrays {
    V3* viewPos;
    F *distance, *sigma;
    V3* color;
    F *spread, *depthSpread;  ///< a destination's: null without depth spreads
    U* members;
    explicit RecordArrays(B& b)
        : viewPos(b.viewPos.data()), distance(b.distance.data()), sigma(b.sigma.data()), color(b.color.data()),
          // A destination without depth spreads gets none; a source is read only where its
          // destination keeps them (then every batch of the stream has them).
          spread(b.spread.data()), depthSpread(std::is_const_v<B> || b.withDepthSpread ? b.depthSpread.data() : nullptr),
          members(b.members.data()) {}
    /// Record @p i of @p src copied to record @p k here.
    void copy(const RecordArrays<const VoxelBatch>& src, size_t i, size_t k) const {
        viewPos[k] = src.viewPos[i];
        distance[k] = src.distance[i];
        sigma[k] = src.sigma[i];
        color[k] = src.color[i];
        spread[k] = src.spread[i];
        if (depthSpread) depthSpread[k] = src.depthSpread[i];
        members[k] = src.members[i];
    }
    /// Records [@p i, @p i + @p n) of @p src copied to [@p k, @p k + @p n) here, array by array.
    void copyRange(const RecordArrays<const VoxelBatch>& src, size_t i, size_t k, size_t n) const {
        std::copy_n(src.viewPos + i, n, viewPos + k);
        std::copy_n(src.distance + i, n, distance + k);
        std::copy_n(src.sigma + i, n, sigma + k);
        std::copy_n(src.color + i, n, color + k);
        std::copy_n(src.spread + i, n, spread + k);
        if (depthSpread) std::copy_n(src.depthSpread + i, n, depthSpread + k);
        std::copy_n(src.members + i, n, members + k);
    }
};
}  // namespace

StreamWindow StreamWindow::of(const VoxelBatch& batch, size_t piece) {
    StreamWindow w;
    w.size = batch.size();
    w.slabBegin = batch.slabBegin, w.slabEnd = batch.slabEnd;
    piece = std::max<size_t>(piece, 1);
    for (size_t i = 0; i < batch.size(); i += piece) w.sources.push_back({&batch, i, i, std::min(piece, batch.size() - i)});
    return w;
}

void StreamWindow::copyTo(VoxelBatch& batch, bool depthSpread) const {
    batch.withDepthSpread = depthSpread;
    batch.resize(size);
    batch.slabBegin = slabBegin, batch.slabEnd = slabEnd;
    const RecordArrays<VoxelBatch> to(batch);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, sources.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t s = r.begin(); s < r.end(); ++s)
            to.copyRange(RecordArrays<const VoxelBatch>(*sources[s].records), sources[s].begin, sources[s].first, sources[s].count);
    });
}

// The sources, in order: the pending voxels in fixed chunks, then each new block's voxels. Each
// source's released (distance < limit) and kept counts, prefix sums, then every source in parallel
// copies its kept records to its offset in pending and, where it is taken only in part, moves its
// released ones to its own front, in order (each source's records are its own, and rewritten only
// at the next window: the chunks' at the next extraction, the pending ones, swapped out, at the
// next release). The window reads each source's released records where they are. The same order
// as a serial append-and-partition, so the windows do not depend on the thread count; and the
// same records as the one batch they were all copied into before session 43.
void VoxelStream::release(size_t blocks, float limit, StreamWindow& window) {
    constexpr size_t kChunk = 4096;
    const size_t pendingChunks = (pending_.size() + kChunk - 1) / kChunk, sources = pendingChunks + blocks;
    const auto source = [&](size_t s, size_t& begin, size_t& end) -> VoxelBatch& {
        if (s < pendingChunks) {
            begin = s * kChunk, end = std::min(pending_.size(), begin + kChunk);
            return pending_;
        }
        const size_t block = s - pendingChunks;
        begin = blockRecords_[block].first, end = blockRecords_[block].second;
        return extracted_[block / kExtractChunk];
    };
    std::vector<size_t> released(sources + 1, 0), kept(sources + 1, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, sources, 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t s = r.begin(); s < r.end(); ++s) {
            size_t begin, end, n = 0;
            const VoxelBatch& src = source(s, begin, end);
            for (size_t i = begin; i < end; ++i) n += src.distance[i] < limit ? 1 : 0;
            released[s + 1] = n, kept[s + 1] = (end - begin) - n;
        }
    });
    for (size_t s = 0; s < sources; ++s) released[s + 1] += released[s], kept[s + 1] += kept[s];
    pendingNext_.withDepthSpread = options_.depthSpread;
    pendingNext_.resize(kept[sources]);
    const RecordArrays<VoxelBatch> toPending(pendingNext_);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, sources, 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t s = r.begin(); s < r.end(); ++s) {
            size_t begin, end, stay = kept[s];
            if (kept[s + 1] == stay) continue;  // released whole: read where it is
            VoxelBatch& batch = source(s, begin, end);
            const RecordArrays<const VoxelBatch> src(batch);
            // A source wholly kept is copied array by array: the same records in the same places.
            if (kept[s + 1] - stay == end - begin) {
                toPending.copyRange(src, begin, stay, end - begin);
                continue;
            }
            // Taken in part: record i is read before anything is written at or after it (front ≤ i).
            const RecordArrays<VoxelBatch> own(batch);
            size_t front = begin;
            for (size_t i = begin; i < end; ++i)
                src.distance[i] < limit ? own.copy(src, i, front++) : toPending.copy(src, i, stay++);
        }
    });
    window.sources.clear();
    window.size = released[sources];
    for (size_t s = 0; s < sources; ++s) {
        size_t begin, end;
        const VoxelBatch& src = source(s, begin, end);
        const size_t n = released[s + 1] - released[s];
        if (n > 0) window.sources.push_back({s < pendingChunks ? &pendingNext_ : &src, begin, released[s], n});  // pending: swapped below
    }
    std::swap(pending_, pendingNext_);
    pendingSwapped_ = !pendingSwapped_;
}

bool VoxelStream::next(VoxelBatch& batch, const std::function<bool(int, int, int, int)>& hidden,
                       const std::function<bool(int, int, int, int)>& partlyHidden) {
    StreamWindow window;
    if (!next(window, hidden, partlyHidden)) return batch.clear(), false;
    window.copyTo(batch, options_.depthSpread);
    return true;
}

bool VoxelStream::next(StreamWindow& window, const std::function<bool(int, int, int, int)>& hidden,
                       const std::function<bool(int, int, int, int)>& partlyHidden) {
    window.sources.clear(), window.size = 0;
    // Room for the largest windows' pending records at once: grown window by window, they were
    // copied at every growth and took fresh pages each time (a one-shot render's most page
    // faults). Reserved, nothing is touched until written; by the records the blocks give, not
    // their voxels (room for a far view's voxels is huge pages it would touch for few).
    if (records_ == 0)
        for (const uint32_t k : order_) records_ += recordsOf(blocks_[k]);
    const size_t room = std::min<size_t>(records_, 2 * options_.maxWindowVoxels);
    if (pending_.viewPos.capacity() < room) pending_.reserve(room, options_.depthSpread), pendingNext_.reserve(room, options_.depthSpread);
    while (true) {
        if (pending_.size() == 0) {
            if (nextBlock_ >= order_.size()) {
                // The two pending buffers back in their places (an odd number of windows swapped
                // them): the next render of the view writes each where this one did, in pages it
                // touched, instead of the other's (19 fresh pages of a warm far checker box, 1024²).
                if (pendingSwapped_) std::swap(pending_, pendingNext_), pendingSwapped_ = false;
                return false;
            }
            // Skip empty depth: jump to the next block's front.
            nextSlab_ = std::max<int64_t>(nextSlab_, int64_t(std::floor(block(nextBlock_).dMin / slabLength_)));
        }
        // The window: at least slabsPerWindow slabs, grown while it would hold too few voxels.
        int64_t slabEnd = nextSlab_ + slabsPerWindow_;
        size_t first = nextBlock_;
        size_t estimate = pending_.size();
        while (nextBlock_ < order_.size() && block(nextBlock_).dMin < slabEnd * slabLength_) {
            estimate += recordsOf(block(nextBlock_));
            ++nextBlock_;
            if (nextBlock_ < order_.size() && estimate < options_.minWindowVoxels && nextBlock_ - first < kMaxWindowBlocks &&
                block(nextBlock_).dMin >= slabEnd * slabLength_)
                slabEnd = int64_t(std::floor(block(nextBlock_).dMin / slabLength_)) + slabsPerWindow_;
        }
        // Activate the blocks whose front the window reached: extract them in parallel, in order.
        // The chunks' buffers are reused window after window (no allocation once warm).
        const size_t count = nextBlock_ - first, chunks = (count + kExtractChunk - 1) / kExtractChunk;
        if (extracted_.size() < chunks) extracted_.resize(chunks);
        skipped_.assign(count, 0);
        blockCounts_.assign(count, StreamCounts{});
        blockRecords_.resize(count);
        // Fixed chunks of kExtractChunk blocks, each appending its blocks' records to one buffer in
        // block order: the chunks, not the threads, own the buffers, so the records do not depend
        // on the thread count.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t c = r.begin(); c < r.end(); ++c) {
                VoxelBatch& e = extracted_[c];
                e.clear();
                const size_t chunkEnd = std::min(count, (c + 1) * kExtractChunk);
                // Room for the chunk's records at once: grown block by block, the arrays were
                // reallocated and copied up to five times per chunk, each time into fresh pages.
                size_t expected = 0;
                for (size_t j = c * kExtractChunk; j < chunkEnd; ++j) expected += recordsOf(block(first + j));
                expected += kLeafRecordSlack;  // the last leaf's vectors may write past its records
                if (e.viewPos.capacity() < expected) e.reserve(expected, options_.depthSpread);
                for (size_t j = c * kExtractChunk; j < chunkEnd; ++j) {
                    const size_t i = first + j;
                    const Block& b = block(i);
                    // The leaf node two blocks ahead (its buffer's pointer and value mask: a miss
                    // each that the next block's buffer prefetch below waited on), then the next
                    // block's values.
                    if (j + 2 < chunkEnd && block(i + 2).leaf) {
                        const char* node = reinterpret_cast<const char*>(block(i + 2).leaf);
                        __builtin_prefetch(node), __builtin_prefetch(node + sizeof(*block(i + 2).leaf) - 1);
                    }
                    if (j + 1 < chunkEnd && block(i + 1).leaf && !momentsKept(block(i + 1))) {
                        const char* next = reinterpret_cast<const char*>(block(i + 1).leaf->buffer().data());
                        for (int line = 0; line < 32; ++line) __builtin_prefetch(next + 64 * line);
                    }
                    const size_t begin = e.size();
                    bool hiddenBlock = false, partly = false;
                    if (hidden) {
                        int x0, y0, x1, y1;
                        screenRect(b, x0, y0, x1, y1);
                        hiddenBlock = hidden(x0, y0, x1, y1);
                        partly = !hiddenBlock && partlyHidden && options_.octantCulling && b.lodLevel == 0 && b.leaf &&
                                 partlyHidden(x0, y0, x1, y1);
                    }
                    std::array<uint64_t, 8> visible;
                    if (hiddenBlock) skipped_[j] = 1;
                    else if (partly && visibleOctants(b, hidden, visible, blockCounts_[j].occluded))
                        extract(b, e, blockCounts_[j], visible.data());
                    else extract(b, e, blockCounts_[j]);
                    blockRecords_[j] = {begin, e.size()};
                }
            }
        });
        for (size_t i = first; i < nextBlock_; ++i) {
            if (skipped_[i - first]) counts_.occluded += block(i).voxels;
            counts_.occluded += blockCounts_[i - first].occluded;
            counts_.aggregates += blockCounts_[i - first].aggregates;
            counts_.aggregatedVoxels += blockCounts_[i - first].aggregatedVoxels;
        }
        // Release the voxels inside the window (pending first, then the new blocks in order);
        // the rest stays pending, in the same order.
        release(count, float(slabEnd * slabLength_), window);
        window.slabBegin = nextSlab_;
        window.slabEnd = slabEnd;
        nextSlab_ = slabEnd;
        adaptWindow(window.size);
        if (window.size > 0) {
            ++windows_;
            largest_ = std::max(largest_, window.size);
            return true;
        }
    }
}

}  // namespace vdbsplat
