// shading/shading_field.h — the shading pass: per-voxel shading factors, computed once per render.
// Owns: ShadingField, a Vec3f tree with the grid's active topology (active tiles voxelized)
// holding each active voxel's (D, S, G) of shading/shading.h, built in parallel (TBB, one
// accessor per task; every voxel is a pure function of the grid, so the result does not depend
// on the thread count), and applyShading(), which the stream and the reference both call on a
// voxel's classification. Pre-shading per voxel keeps DESIGN §1's model: the forward modes and
// the reference integrate the same field of σ_k and c_k, only c_k (and σ_k with gradient
// opacity) now depend on the neighbours and the eye.
#pragma once
#include <openvdb/openvdb.h>

#include <glm/glm.hpp>

#include "shading/shading.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

class ShadingField {
public:
    using Tree = openvdb::Vec3fTree;  ///< per active voxel: (D, S, G)
    using Leaf = Tree::LeafNodeType;
    using Accessor = openvdb::tree::ValueAccessor<const Tree>;  ///< one per thread, never shared

    /// @brief Shades every active voxel of @p volume that @p table gives a positive extinction
    /// (the others keep (1, 0, 1)). Values are normalised with [@p lo, @p hi] (the range the
    /// table was baked for), clamped to [0, 1]; inactive neighbours read as the grid's background.
    /// @p eye: the camera position in world space (headlight and view direction).
    ShadingField(const Volume& volume, const ClassificationTable& table, float lo, float hi, const glm::dvec3& eye,
                 const ShadingSettings& settings);

    /// @brief The leaf at @p origin (a leaf's or an 8³ tile block's origin), nullptr if none.
    const Leaf* leaf(const openvdb::Coord& origin) const { return tree_->probeConstLeaf(origin); }
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
