// shading/shading_field.h — shading the voxels: per-voxel factors, the same for every mode.
// Owns: VoxelShader, the per-render function voxel → (D, S, G) of shading/shading.h (a pure
// function of the grid, the camera position and the settings); ShadingField, a Vec3f tree with
// the grid's active topology (active tiles voxelized) holding every active voxel's factors,
// built in parallel (TBB, one accessor per task) for the reference, which reads each voxel many
// times; and applyShading(), which the stream and the reference both call on a voxel's
// classification. The forward modes shade in the stream's parallel extraction, voxel by voxel,
// only the voxels they draw (a full field costs more in first-touch page faults than the
// lighting itself on this VM); both paths call the same VoxelShader, so their factors are
// identical and the result does not depend on the thread count. Pre-shading per voxel keeps DESIGN §1's model: the forward modes and
// the reference integrate the same field of σ_k and c_k, only c_k (and σ_k with gradient
// opacity) now depend on the neighbours and the eye.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <glm/glm.hpp>

#include "shading/shade_leaf.h"
#include "shading/shading.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief Shades single voxels: the one function both families of modes get their factors from.
/// Immutable after construction, shared by every thread; each thread passes its own accessor.
class VoxelShader {
public:
    using FloatLeaf = openvdb::FloatTree::LeafNodeType;
    /// Unregistered (the grid does not change during a render): cheap to make per block.
    using Accessor = openvdb::tree::ValueAccessor<const openvdb::FloatTree, false>;

    /// @p table: voxels it gives no extinction stay unshaded (1, 0, 1). Values are normalised
    /// with [@p lo, @p hi] (the range the table was baked for), clamped to [0, 1]; inactive
    /// neighbours read as the grid's background. @p eye: the camera position in world space.
    VoxelShader(const Volume& volume, const ClassificationTable& table, float lo, float hi, const glm::dvec3& eye,
                const ShadingSettings& settings);

    /// @brief (D, S, G) of the active voxel @p ijk with value @p value. @p leaf: the grid's leaf
    /// holding it and @p n its offset there (nullptr for a voxel of an active tile: every
    /// neighbour is then read through @p acc). The result does not depend on which path reads.
    openvdb::Vec3f operator()(Accessor& acc, const FloatLeaf* leaf, openvdb::Index n,
                              const openvdb::Coord& ijk, float value) const;
    /// @brief The same for a voxel the caller has classified to σ > 0 (the stream's classifier):
    /// operator() without classifying it again (which was 7 % of a shaded far view).
    openvdb::Vec3f shadeDrawn(Accessor& acc, const FloatLeaf* leaf, openvdb::Index n, const openvdb::Coord& ijk) const;
    /// @brief Every voxel's factors of @p leaf at once, vectorised (shading/shade_leaf.h): for
    /// each active voxel n the table may draw (its index not below transparentBelow) the (D, S, G)
    /// shadeDrawn gives, bit for bit; (1, 0, 1), unshaded, for the others.
    /// @return false, writing nothing, where leafShadingSupported() does not hold.
    bool shadeLeaf(Accessor& acc, const FloatLeaf& leaf, LeafFactors& out) const;

    const Volume& volume() const { return volume_; }

private:
    const Volume& volume_;
    const ClassificationTable& table_;
    ShadingSettings settings_;
    glm::mat3 gradientToWorld_;  ///< transpose of worldToIndex's linear part: ∇_world = Aᵀ ∇_index
    glm::dvec3 eye_;
    glm::vec3 toLight_{0.f};     ///< directional light (unit), when settings_.hasLight
    float background_, lo_, hi_;
};

/// @brief Every active voxel's factors, computed once (the reference reads each voxel many times).
class ShadingField {
public:
    using Tree = openvdb::Vec3fTree;  ///< per active voxel: (D, S, G)
    using Leaf = Tree::LeafNodeType;
    using Accessor = openvdb::tree::ValueAccessor<const Tree>;  ///< one per thread, never shared

    /// @brief Shades every active voxel with @p shader, in parallel (active tiles voxelized).
    explicit ShadingField(const VoxelShader& shader);

    const Tree& tree() const { return *tree_; }
    /// Seconds the pass took.
    double seconds() const { return seconds_; }

private:
    Tree::Ptr tree_;
    double seconds_ = 0.0;
};

/// @brief The shaded classification: colour c·D + S, extinction σ·G.
inline Classified applyShading(const Classified& c, const openvdb::Vec3f& f) {
    return {c.color * f[0] + glm::vec3(f[1]), c.sigma * f[2]};
}

/// @brief The gradient of the normalised values at @p ijk by central differences (index space,
/// normalised value per voxel), as the shading pass computes it (tests).
glm::vec3 gradientAt(openvdb::FloatGrid::ConstAccessor& acc, const openvdb::Coord& ijk, float background,
                     float lo, float hi);

}  // namespace vdbsplat
