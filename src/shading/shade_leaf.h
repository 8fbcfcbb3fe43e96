// shading/shade_leaf.h — the shading factors of a whole 8³ leaf at once, vectorised.
// Owns: LeafShadingInput (a leaf's normalised values padded by its six face neighbours, and the
// render's constants), LeafFactors (every voxel's (D, S, G)) and shadeLeafRows, which evaluates
// shading/shading.h's gradient and Blinn–Phong model for the leaf's 64 rows of 8 voxels with
// Google Highway (runtime dispatch), operation for operation as VoxelShader::shadeDrawn does for
// one voxel, so the factors are its factors bit for bit (the file is compiled without
// contraction; powf and expm1 are libm's, called per lane that needs them). VoxelShader::shadeLeaf
// (shading/shading_field.h) fills the input and is what callers use.
#pragma once
#include <glm/glm.hpp>

#include "shading/shading.h"

namespace vdbsplat {

/// @brief One leaf's shading inputs: its values normalised ([0, 1], as the gradient reads them)
/// on a 10³ grid, the leaf at [1, 8]³ and each face neighbour's layer around it (edges and
/// corners unused), and the constants VoxelShader holds.
struct LeafShadingInput {
    static constexpr int kSide = 10;  ///< padded side: voxel (x, y, z) at ((x+1)·10 + y+1)·10 + z+1
    alignas(64) float padded[kSide * kSide * kSide];
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
/// neighbour values (all 512, active or not: callers read the voxels they draw).
/// leafShadingSupported() must hold.
void shadeLeafRows(const LeafShadingInput& in, LeafFactors& out);

}  // namespace vdbsplat
