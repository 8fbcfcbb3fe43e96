// footprint/reindex.h — the perspective-correct footprint index (DESIGN §3).
// Owns: d(i, α), the normalised distance from the kernel centre to the ray whose
// affine ellipse index is i, for a sphere of half cone angle α (Yuan et al. 2003,
// §4 / Appendix A, with the denominator corrected — see below).
//
// A ray at angle β from the cone axis has tan β = i·tan α (exact on-axis) and passes
// at distance D·sin β from the centre; the silhouette (β = α) is at distance r = D·sin α:
//     d(i, α) = sin(atan(i·tan α)) / sin α  =  i / √(cos²α + i²·sin²α).
// The seed paper prints the denominator as tan α, which gives d(1) = cos α ≠ 1; the
// brute-force test tests/footprint/reindex_test.cpp (ray–centre distance on-axis)
// settles that sin α is right and fails for the misprint (reindexMisprinted below).
#pragma once

namespace vdbsplat {

/// @brief d(i, α) (DESIGN §3), the normalised ray–centre distance; d(0)=0, d(1)=1.
/// @param i affine index in [0, 1]; @param alpha half cone angle in radians, [0, π/2).
/// α = 0 gives the limit d = i.
double reindex(double i, double alpha);

/// @brief d² as a function of i² (what the tables store): i² / (cos²α + i²·sin²α).
double reindex2(double i2, double alpha);

/// @brief The seed paper's misprinted formula sin(atan(i·tan α)) / tan α, kept ONLY so the
/// regression test can show that it disagrees with the brute force. Never use it.
double reindexMisprinted(double i, double alpha);

}  // namespace vdbsplat
