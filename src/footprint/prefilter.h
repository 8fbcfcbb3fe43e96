// footprint/prefilter.h — the screen-space low-pass (anti-aliasing) prefilter h_p.
// Owns: its constants, and the ramp that eases a primitive's share of it with its magnification
// (PrefilterRamp). EWA (Zwicker et al. 2001, §5: the resampling filter is the
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

/// The low-pass folded into a primitive of projected voxel spacing s, where the renderer folds
/// only part of V_h into its primitives and applies the rest to the image (the postfilter order,
/// render/postfilter.h): `minified` up to s = ½ pixel of the grid it composites on, easing
/// linearly to `magnified` at 1 pixel and beyond (where a point's own filter variance (s_g·s)²
/// already moves it smoothly: V_s matters only below). A function of the spacing alone, for points and
/// splats alike and whatever the point/splat threshold, so a voxel carries the same low-pass on
/// both sides of the switch (DESIGN §4: no seam); far points keep what moves them smoothly, and
/// magnified splats, whose own footprint is pixels wide, carry less of what is error before the
/// exponential (docs/fidelity.md, "Session 26"). The same double operations wherever it is
/// evaluated (the scalar projection, its lanes, the compositor's per-tile recompute), so the
/// same value bit for bit.
struct PrefilterRamp {
    static constexpr double kStart = 0.5;     ///< s (px) up to which V is `minified`
    static constexpr double kInvWidth = 2.0;  ///< 1/(the ramp's length): `magnified` from s = 1

    double minified = kPrefilterVariance;  ///< V at s ≤ kStart (px²)
    double span = 0.0;                     ///< minified − magnified

    PrefilterRamp() = default;
    PrefilterRamp(double minifiedVariance, double magnifiedVariance)
        : minified(minifiedVariance), span(minifiedVariance - magnifiedVariance) {}
    /// V at spacing @p s (px): minified − span·clamp((s − kStart)·kInvWidth, 0, 1); minified
    /// where s is NaN.
    double at(double s) const {
        const double t = (s - kStart) * kInvWidth;
        if (!(t > 0.0)) return minified;
        return t < 1.0 ? minified - span * t : minified - span;
    }
};

}  // namespace vdbsplat
