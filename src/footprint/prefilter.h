// footprint/prefilter.h — the screen-space low-pass (anti-aliasing) prefilter h_p.
// Owns: its one constant. EWA (Zwicker et al. 2001, §5: the resampling filter is the
// footprint convolved with a low-pass of variance V_h = I) and the reference
// renderer (DESIGN §1: band-limit the continuous image by h_p before sampling)
// must use the same filter, or every PSNR against the reference measures a
// mismatch of filters instead of the resampling error.
#pragma once

namespace vdbsplat {

/// Variance of the Gaussian prefilter in pixel² (EWA's V_h = I).
inline constexpr double kPrefilterVariance = 1.0;
/// The prefilter is truncated at this many standard deviations (weights renormalised).
inline constexpr double kPrefilterCutoffSigmas = 3.0;

}  // namespace vdbsplat
