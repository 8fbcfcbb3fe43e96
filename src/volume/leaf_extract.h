// volume/leaf_extract.h — one leaf's voxels as stream records, vectorised.
// Owns: LeafRecords (where they go) and extractLeafVoxels, which classifies a whole 8³ leaf
// through the baked table a vector of rows at a time (volume/classify-inl.h) and writes, for every
// active voxel with σ > 0 in OpenVDB's order, its view position, distance to the eye, σ and
// colour. Google Highway, runtime dispatch. The stream's voxel-by-voxel extraction
// (VoxelStream::extractVoxels) is the oracle it equals bit for bit: the same float operations
// for the classification, glm's own order for the double view position (dmat4 · dvec4: (m₀X +
// m₁Y) + (m₂Z + m₃)) and length ((x² + y²) + z²), no fused multiply-adds.
#pragma once
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

#include "shading/shade_leaf.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief Room past a leaf's records that extractLeafVoxels may write (and leave undefined): a
/// vector of records is stored whole, however few of its lanes are kept.
inline constexpr size_t kLeafRecordSlack = 16;

/// @brief Arrays with room for the leaf's active voxels plus kLeafRecordSlack records each (or
/// for 512: a vector never ends past the leaf's voxels).
struct LeafRecords {
    glm::vec3* viewPos;
    float* distance;
    float* sigma;
    glm::vec3* color;
};

/// @brief True when this CPU's widest vectors hold whole 8-voxel rows (as leafMomentsSupported).
bool leafExtractSupported();

/// @brief Writes the records of the leaf at index @p origin (its first voxel) whose @p values are in
/// OpenVDB's order (n = x·64 + y·8 + z) and @p maskWords its 8 value-mask words (nullptr: dense),
/// through @p indexToView; returns how many. It may write up to kLeafRecordSlack records past them
/// (the caller cuts them off). With @p factors, each voxel is shaded as applyShading
/// does (c·D + S, σ·G) before the σ > 0 test. @p table must not be empty(); leafExtractSupported()
/// must hold.
size_t extractLeafVoxels(const float* values, const uint64_t* maskWords, const ClassificationTable& table,
                         const glm::dmat4& indexToView, const glm::ivec3& origin, const LeafRecords& out,
                         const LeafFactors* factors = nullptr);

}  // namespace vdbsplat
