// footprint/swan.h — Swan et al. 1997's anti-aliased splat (DESIGN §6, `--mode swan`).
// Owns: the uniform stretch of a minified voxel's footprint to the pixel filter's size, with
// the amplitude scaled so that the deposit's total is unchanged.
//
// Swan, Mueller, Möller, Shareef, Crawfis, Yagel 1997 ("An Anti-Aliasing Technique for
// Splatting"), its anti-aliasing method, cited by name: when the projected voxel spacing falls
// below the screen's sampling rate, the splat kernel is scaled up in screen space by the ratio of
// the two rates, and its height down by the same factor squared (for a 2D footprint) so that its
// integral is kept.
// Here the "rate" of the screen is the pixel filter: the stretch s makes the footprint's narrowest
// standard deviation at least the low-pass's √V_h,
//     s = max(1, √V_h / σ_min),   σ_min = b·s_g/R   (b the exact ellipse's minor semi-axis),
//     a' = s·a,  b' = s·b,  amplitude = 1/s²       (the total ∝ a'·b'·amplitude is unchanged).
// The stretch is uniform (Swan's), so the ellipse keeps its axes and its (i, α) reindex row:
// the table path draws it like any splat. Magnified voxels are hybrid splats (ScreenKernel).
#pragma once
#include "footprint/screen_kernel.h"

namespace vdbsplat {

/// @brief Swan's stretched kernel of the Ellipse @p e for the pixel filter variance
/// @p prefilterVariance (px²): s = max(1, √V_h·R/(s_g·b)); with s = 1 the unfiltered ellipse.
/// @throw std::invalid_argument when @p e is not an Ellipse.
ScreenKernel makeSwanKernel(const SphereProjection& e, double prefilterVariance = kPrefilterVariance,
                            const KernelShape& kernel = KernelShape::standard());

/// @brief The stretch factor s of makeSwanKernel (≥ 1).
double swanStretch(const SphereProjection& e, double prefilterVariance = kPrefilterVariance,
                   const KernelShape& kernel = KernelShape::standard());

}  // namespace vdbsplat
