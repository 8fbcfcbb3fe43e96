// render/postfilter.h — the screen prefilter applied after compositing (--filter-order postfilter).
// Owns: the sub-pixel grid the forward modes composite on, its camera, and the separable
// Gaussian that band-limits the composited sub-pixel image and samples it at pixel centres.
//
// DESIGN §1: a pixel is h_p ∗ C, the prefilter applied to the composited image. EWA (Zwicker et
// al. 2001, eq. 18–20: ρ = (reconstruction footprint) ⊗ h) folds h_p into each primitive's
// optical depth before compositing instead; for structures one or two pixels wide
// exp(−h_p∗τ) is darker than h_p∗exp(−τ) (Jensen; DESIGN §8.3). Here the primitives carry
// only a small low-pass (in sub-pixels², so the sub-pixel grid does not alias): V_s when
// minified, easing to V_m ≤ V_s when magnified (PrefilterRamp, footprint/prefilter.h); and the
// image gets the rest: with k sub-pixels per axis,
//     V_post = V_h − V_m / k²          [px²]
// so the total low-pass is V_h for a magnified primitive and at most (V_s − V_m)/k² more for a
// minified one (Gaussian variances add under convolution), and only V_s/k² or less of it is
// applied before the exponential. Energy is unchanged: each primitive's
// deposit keeps its total (DESIGN §4), and the weights of every output pixel sum to 1.
#pragma once
#include <vector>

#include "camera/camera.h"
#include "image/image.h"

namespace vdbsplat {

/// Low-pass kept on the primitives of the sub-pixel grid, in sub-pixel². Smaller is closer to
/// the reference on every volume measured (0.5 → 0.25 → 0.1 → 0.05: tubes 160² 34.1 → 38.6 →
/// 45.5 → 50.7 dB at k = 1; docs/fidelity.md "Thin dense structures"); 0.1 keeps a point's
/// deposit spread over a few pixels (σ ≈ 0.3) so that it still moves with its sub-pixel
/// position instead of snapping to the nearest pixel.
inline constexpr double kSubpixelPrefilterVariance = 0.1;

/// The low-pass kept on magnified primitives (projected spacing ≥ 1 sub-pixel; PrefilterRamp
/// eases to it from V_s at ½), in sub-pixel²: a splat is a kernel a pixel or more wide that moves with its
/// centre, so the point's reason for V_s does not apply, and every bit folded in before the
/// exponential is error against the reference. Against V_s everywhere (400², `--spp 16`
/// references; docs/fidelity.md, "Session 26"): the framed Engine 64.58 → 69.25 dB, the framed
/// tubes 59.41 → 64.00, every framed and close cell better or equal, the far cells unchanged but
/// for the postfilter's 0.05 px² less (−0.13 to +1.7 dB).
inline constexpr double kSubpixelMagnifiedVariance = 0.05;

struct SubpixelGrid {
    int k = 1;                    ///< sub-pixels per pixel and axis
    int border = 0;               ///< pixels rendered beyond each image edge (the filter's reach)
    double fineVariance = 0.0;    ///< V_s, sub-pixel²: minified primitives' (ProjectionContext::prefilterVariance)
    double magnifiedVariance = 0.0;  ///< V_m ≤ V_s, sub-pixel²: magnified ones' (ProjectionContext::magnifiedPrefilterVariance)
    /// V_post = V_h − V_m/k², px²: a magnified primitive's low-pass is V_h in all, a minified
    /// one's V_h + (V_s − V_m)/k² (0.05 px² more at k = 1).
    double postVariance = 0.0;
};

/// @brief The grid for @p k sub-pixels per axis (k ≥ 1) and the prefilter @p prefilterVariance.
SubpixelGrid makeSubpixelGrid(int k, double prefilterVariance);

/// @brief The camera of the sub-pixel image: same eye, look-at and focal point per pixel ×k,
/// k·(W + 2·border) × k·(H + 2·border) sub-pixels. Sub-pixel i's centre lies at pixel
/// coordinate (i + 0.5)/k − border.
Camera subpixelCamera(const Camera& camera, const SubpixelGrid& grid);

/// @brief The 1D taps: output pixel x reads sub-pixel k·(x + border) + first + j with weight
/// weights[j]; Gaussian of variance postVariance truncated at kPrefilterCutoffSigmas, sum 1.
struct PostfilterTaps {
    int first = 0;
    std::vector<float> weights;
};
PostfilterTaps postfilterTaps(const SubpixelGrid& grid);

/// @brief Band-limits the composited sub-pixel image @p fine (from subpixelCamera) by the
/// Gaussian of grid.postVariance and samples it at the centres of a @p width × @p height image.
/// Separable, rows in parallel; the result does not depend on the thread count.
Image postfilterImage(const Image& fine, const SubpixelGrid& grid, int width, int height);

/// @brief postfilterImage's pixels written into @p out at (@p x0, @p y0), its other pixels left as
/// they are, straight from the compositor's frame: a band of output rows at a time, each filtering
/// the sub-pixel rows it reads into a buffer its thread keeps, so that no full-size intermediate
/// (nor the copy into the final image) is made. The same sums in the same order as postfilterImage.
/// @throw Error when @p fine or @p out do not match the grid and the rectangle.
void postfilterInto(const FrameView& fine, const SubpixelGrid& grid, int width, int height, Image& out, int x0, int y0);
void postfilterInto(const Image& fine, const SubpixelGrid& grid, int width, int height, Image& out, int x0, int y0);

}  // namespace vdbsplat
