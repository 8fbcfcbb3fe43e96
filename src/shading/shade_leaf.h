// shading/shade_leaf.h — the shading factors of a whole 8³ leaf at once, vectorised.
// Owns: LeafShadingInput (a leaf's values, its six face neighbours' layers, and the render's
// constants), LeafFactors (every voxel's (D, S, G)) and shadeLeafRows, which evaluates
// shading/shading.h's gradient and Blinn–Phong model for the leaf's 64 rows of 8 voxels with
// Google Highway (runtime dispatch), operation for operation as VoxelShader::shadeDrawn does for
// one voxel, so the factors are its factors bit for bit (the file is compiled without
// contraction; powf and expm1 are libm's, called per lane that needs them). VoxelShader::shadeLeaf
// (shading/shading_field.h) fills the input and is what callers use.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

#include "shading/shading.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief One leaf's shading inputs: its values and value mask, each face neighbour's layer of
/// raw values beside it (what the gradient reads there), and the constants VoxelShader holds.
struct LeafShadingInput {
    const float* values = nullptr;      ///< the leaf's 512 values, n = x·64 + y·8 + z
    uint64_t maskWords[8] = {};         ///< its value mask (word x: bit y·8 + z); off reads as background
    /// Face neighbours' raw values (an inactive one: the background), face 2·axis + (0: −, 1: +),
    /// at u·8 + v for the two other axes in order (axis + 1, axis + 2) mod 3.
    float faces[6][64];
    float background = 0.f, lo = 0.f, scale = 1.f;  ///< normalised value: clamp((v − lo)·scale, 0, 1)
    /// The baked table (not null): the voxels it may draw are active, finite, and their index is
    /// not below transparentBelow; the others are not shaded (factors (1, 0, 1)).
    const ClassificationTable* table = nullptr;
    glm::ivec3 origin{0};              ///< the leaf's first voxel (index space)
    glm::dmat4 indexToWorld{1.0};
    glm::dvec3 eye{0.0};               ///< the camera position, world space
    glm::mat3 gradientToWorld{1.f};    ///< ∇_world = Aᵀ ∇_index
    glm::vec3 toLight{0.f};            ///< directional light (unit), used when hasLight
    ShadingSettings settings;
};

/// @brief (D, S, G) of every voxel of the leaf, n = x·64 + y·8 + z (OpenVDB's order).
struct LeafFactors {
    static constexpr int kVoxels = 512;
    alignas(64) float diffuse[kVoxels];
    alignas(64) float specular[kVoxels];
    alignas(64) float opacity[kVoxels];
};

/// @brief True when this CPU runs shadeLeafRows (vectors of 8 floats: AVX2 and wider).
bool leafShadingSupported();

/// @brief Every voxel's factors, as VoxelShader::shadeDrawn computes them from the same
/// neighbour values, for every voxel the table may draw, and (1, 0, 1) for the others. leafShadingSupported() must hold.
void shadeLeafRows(const LeafShadingInput& in, LeafFactors& out);

}  // namespace vdbsplat
