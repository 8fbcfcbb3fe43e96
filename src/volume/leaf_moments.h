// volume/leaf_moments.h — the level-of-detail moments of one whole 8³ leaf, vectorised.
// Owns: CellMoments (the sums an aggregate is built from, DESIGN §8.2) and leafMoments, which
// classifies a leaf's 512 values through the baked table and sums, for every level-of-detail
// cell of the leaf (2³, 4³ or the whole 8³), its mass Σσ, emission Σσc, first moments Σσ·d and
// second moments Σσ·d dᵀ about the cell's centre (index units). Google Highway,
// runtime dispatch (one binary, the widest vectors the CPU has). The stream's scalar row-by-row
// sums (volume/stream.cpp) are the oracle it is tested against.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

#include "shading/shade_leaf.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief σ-weighted sums over the voxels of one cell, about the cell's centre (index units).
struct CellMoments {
    float m = 0.f;                    ///< Σσ (σ per voxel length)
    glm::vec3 emission{0.f};          ///< Σσ·c
    glm::vec3 first{0.f};             ///< Σσ·d
    float xx = 0.f, yy = 0.f, zz = 0.f, xy = 0.f, xz = 0.f, yz = 0.f;  ///< Σσ·d dᵀ
    uint32_t n = 0;                   ///< voxels with σ > 0
};

/// @brief True when this CPU's widest vectors hold whole 8-voxel rows (8 or 16 float lanes:
/// AVX2, AVX-512); otherwise leafMoments does nothing and the caller takes the scalar sums.
bool leafMomentsSupported();

/// @brief The moments of every cell of (2^@p level)³ voxels of one 8³ leaf (@p level 1–3), about
/// each cell's centre: @p values in OpenVDB's order (n = x·64 + y·8 + z), @p maskWords its 8
/// value-mask words (word x holds bit y·8 + z), or nullptr for a dense leaf; each active value
/// classified exactly as ClassificationTable::operator() does (non-finite: σ = 0), then, with
/// @p factors, shaded as applyShading does (c·D + S, σ·G). Writes (8 >> level)³ cells to @p out,
/// cell (cx, cy, cz) at (cx·c + cy)·c + cz. @p table must not be empty(); leafMomentsSupported()
/// must hold.
void leafMoments(const float* values, const uint64_t* maskWords, const ClassificationTable& table, int level,
                 CellMoments* out, const LeafFactors* factors = nullptr);

}  // namespace vdbsplat
