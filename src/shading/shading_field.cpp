// shading/shading_field.cpp — the parallel shading pass (see shading_field.h).
#include "shading/shading_field.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace vdbsplat {

namespace {

/// A raw value normalised with [lo, hi] and clamped to [0, 1] (the classification's x).
float normalised(float v, float lo, float scale) { return std::clamp((v - lo) * scale, 0.f, 1.f); }

/// The central-difference gradient of six raw neighbour values (−x, +x, −y, +y, −z, +z).
glm::vec3 gradientOf(const float raw[6], float lo, float hi) {
    const float scale = 1.f / (hi - lo);
    float n[6];
    for (int k = 0; k < 6; ++k) n[k] = normalised(raw[k], lo, scale);
    return centralDifference(n);
}

using FloatLeaf = openvdb::FloatTree::LeafNodeType;

/// The six neighbours' raw values of voxel @p n (leaf offset) at @p ijk: read from @p leaf
/// directly where the neighbour is inside it (an inactive one reads as the background), through
/// @p acc otherwise — the same values gradientAt() reads, at a fraction of the cost.
template <typename AccessorT>
void neighbourValues(const FloatLeaf* leaf, openvdb::Index n, const openvdb::Coord& ijk, AccessorT& acc,
                     float background, float out[6]) {
    static constexpr openvdb::Index kStride[3] = {FloatLeaf::DIM * FloatLeaf::DIM, FloatLeaf::DIM, 1};
    const openvdb::Coord local = ijk - (leaf ? leaf->origin() : ijk);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            float& v = out[2 * axis + side];
            const bool inside = leaf && (side == 0 ? local[axis] > 0 : local[axis] < int(FloatLeaf::DIM) - 1);
            if (inside) {
                const openvdb::Index m = side == 0 ? n - kStride[axis] : n + kStride[axis];
                v = leaf->isValueOn(m) ? leaf->getValue(m) : background;
            } else {
                openvdb::Coord q = ijk;
                q[axis] += side == 0 ? -1 : 1;
                if (!acc.probeValue(q, v)) v = background;
            }
        }
}

}  // namespace

glm::vec3 gradientAt(openvdb::FloatGrid::ConstAccessor& acc, const openvdb::Coord& ijk, float background, float lo,
                     float hi) {
    float raw[6];
    neighbourValues(nullptr, 0, ijk, acc, background, raw);
    return gradientOf(raw, lo, hi);
}

VoxelShader::VoxelShader(const Volume& volume, const ClassificationTable& table, float lo, float hi,
                         const glm::dvec3& eye, const ShadingSettings& settings)
    : volume_(volume), table_(table), settings_(settings),
      gradientToWorld_(glm::transpose(glm::mat3(glm::dmat3(volume.worldToIndex)))), eye_(eye),
      background_(volume.tree->background()), lo_(lo), hi_(hi > lo ? hi : lo + 1.f) {
    if (settings.hasLight) toLight_ = glm::vec3(glm::normalize(settings.light));
}

openvdb::Vec3f VoxelShader::operator()(Accessor& acc, const FloatLeaf* leaf, openvdb::Index n,
                                       const openvdb::Coord& ijk, float value) const {
    if (!(table_.sigma(value) > 0.f)) return {1.f, 0.f, 1.f};  // drawn by nobody: leave it unshaded
    return shadeDrawn(acc, leaf, n, ijk);
}

openvdb::Vec3f VoxelShader::shadeDrawn(Accessor& acc, const FloatLeaf* leaf, openvdb::Index n, const openvdb::Coord& ijk) const {
    float raw[6];
    neighbourValues(leaf, n, ijk, acc, background_, raw);
    const glm::vec3 g = gradientOf(raw, lo_, hi_);
    const float magnitude = glm::length(g);
    const glm::dvec3 x(volume_.indexToWorld * glm::dvec4(ijk.x(), ijk.y(), ijk.z(), 1.0));
    const glm::dvec3 toEyeD = eye_ - x;
    const double eyeDistance = glm::length(toEyeD);
    const glm::vec3 toEye = eyeDistance > 0.0 ? glm::vec3(toEyeD / eyeDistance) : glm::vec3(0.f);
    const glm::vec3 toLight = settings_.hasLight ? toLight_ : toEye;
    const ShadingFactors f = shadeVoxel(gradientToWorld_ * g, magnitude, toEye, toLight, settings_);
    return {f.diffuse, f.specular, gradientOpacityFactor(magnitude, settings_.gradientOpacity)};
}

bool VoxelShader::shadeLeaf(Accessor& acc, const FloatLeaf& leaf, LeafFactors& out) const {
    if (!leafShadingSupported()) return false;
    LeafShadingInput in;
    in.values = leaf.buffer().data();
    for (int x = 0; x < 8; ++x) in.maskWords[x] = leaf.getValueMask().getWord<uint64_t>(openvdb::Index(x));
    // Each face neighbour's layer: from its leaf, or, where there is none, the tile or background
    // value that covers the whole 8³ region beside the leaf (what probeValue reads at each voxel).
    const openvdb::Coord origin = leaf.origin();
    constexpr int kDim = int(FloatLeaf::DIM);
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            openvdb::Coord q = origin;
            q[axis] += side == 0 ? -kDim : kDim;
            float* layer = in.faces[2 * axis + side];
            const FloatLeaf* beside = acc.probeConstLeaf(q);
            if (!beside) {
                float tile = background_;
                if (!acc.probeValue(q, tile)) tile = background_;
                std::fill_n(layer, 64, tile);
                continue;
            }
            for (int u = 0; u < kDim; ++u)
                for (int v = 0; v < kDim; ++v) {
                    openvdb::Coord c;  // in the neighbour: its last layer (−) or first (+) along axis
                    c[axis] = side == 0 ? kDim - 1 : 0, c[(axis + 1) % 3] = u, c[(axis + 2) % 3] = v;
                    const openvdb::Index m = FloatLeaf::coordToOffset(c);
                    layer[u * kDim + v] = beside->isValueOn(m) ? beside->getValue(m) : background_;
                }
        }
    in.background = background_, in.lo = lo_, in.scale = 1.f / (hi_ - lo_);  // as gradientOf normalises
    in.table = &table_;
    in.origin = glm::ivec3(origin.x(), origin.y(), origin.z());
    in.indexToWorld = volume_.indexToWorld;
    in.eye = eye_;
    in.gradientToWorld = gradientToWorld_;
    in.toLight = toLight_;
    in.settings = settings_;
    shadeLeafRows(in, out);
    return true;
}

ShadingField::ShadingField(const VoxelShader& shader) {
    const auto start = std::chrono::steady_clock::now();
    const openvdb::FloatTree& values = *shader.volume().tree;
    const openvdb::Vec3f unshaded(1.f, 0.f, 1.f);
    tree_ = std::make_shared<Tree>(values, unshaded, unshaded, openvdb::TopologyCopy());
    tree_->voxelizeActiveTiles();
    std::vector<Leaf*> leaves;
    leaves.reserve(tree_->leafCount());
    tree_->getNodes(leaves);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 8), [&](const tbb::blocked_range<size_t>& r) {
        VoxelShader::Accessor acc(values);  // one per task, never shared
        for (size_t i = r.begin(); i < r.end(); ++i) {
            Leaf& leaf = *leaves[i];
            const FloatLeaf* source = values.probeConstLeaf(leaf.origin());  // null: a voxelized tile
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Coord ijk = it.getCoord();
                const float value = source ? source->getValue(it.pos()) : acc.getValue(ijk);
                it.setValue(shader(acc, source, it.pos(), ijk, value));
            }
        }
    });
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace vdbsplat
