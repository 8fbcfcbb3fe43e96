// pointfilter/point_filter.h — the circular pixel filter w of a minified voxel (DESIGN §4).
// Owns: the point's filter variance, its total optical depth (the energy rule that
// must equal the splat's summed deposit at the threshold), the 1D Gaussian weight of
// r²/V, and the per-point rasterization into at most 7×7 pixels.
//
// For a point the EWA resampling filter (Zwicker et al. 2001) is the voxel's
// projected footprint convolved with the low-pass, both ≈ Gaussian:
//     V_point = kPrefilterVariance + (s_g · h·f/z)²            [px²]
// — exactly the variance of the widened splat kernel of the same voxel on-axis
// (footprint/screen_kernel.h), so the two converge at the threshold.
// w is evaluated separably (one 1D weight per row and per column: the Gaussian
// factors) and
// truncated at r_s = min(3·√V_point, 3.5 px) (≤ 7×7 pixel centres) and
// renormalised so that its DISCRETE sum over the pixel centres is exactly 1: then
// the point's total deposit is exactly pointDepositTotal(), whatever its sub-pixel
// position (the continuous ∫w = 1 would lose ≈ 1.1% to the 3σ truncation).
#pragma once
#include <array>
#include <bit>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "camera/camera.h"
#include "footprint/kernel.h"
#include "footprint/prefilter.h"

namespace vdbsplat {

inline constexpr double kPointSupportSigmas = 3.0;  ///< truncation of w in standard deviations
inline constexpr double kPointMaxRadiusPx = 3.5;    ///< r_s cap: at most 7 pixel centres per axis
inline constexpr int kPointMaxSide = 7;             ///< 2·kPointMaxRadiusPx

/// @brief V_point = kPrefilterVariance + (s_g·@p projectedSpacingPx)² in px², where the
/// projected voxel spacing is h·f/z pixels (DESIGN §4).
/// @param prefilterVariance the low-pass V_h in px² (the postfilter order passes a smaller one).
/// @param kernelSigma the reconstruction kernel's s_g (voxels; the standard kernel's by default).
double pointFilterVariance(double projectedSpacingPx, double prefilterVariance = kPrefilterVariance,
                           double kernelSigma = Kernel::kSigma);

/// @brief The point's total optical depth summed over pixels (DESIGN §4):
///     σ · M · (f/z)² · (D/z),   M = h³ (the kernel's volume integral in world units).
/// M·(f/z)² = h·(h·f/z)²: a length times the projected voxel area in px². The factor
/// D/z = 1/cosθ is the exact screen-space total of a small kernel off-axis (pixels
/// subtend dΩ = cos³θ/f² there); DESIGN §4's σ·M·(f/z)² is its on-axis value. With it the
/// energy test holds off-axis too (tests/pointfilter). Returns 0 for z ≤ 0.
/// @param sigma extinction per world unit; @param h voxel size (world);
/// @param f focal length (px); @param c view-space voxel centre.
double pointDepositTotal(double sigma, double h, double f, const ViewPoint& c);

/// The constants of pointFilterWeight (below): its support, the polynomial's degree and
/// coefficients, and the scale from x to the exponent of 2. Shared with the vector weight
/// (point_weight-inl.h), which must use the same floats.
namespace point_filter_weight {
inline constexpr double kMaxX = kPointSupportSigmas * kPointSupportSigmas;
inline constexpr int kDegree = 6;  ///< 2^f's Taylor polynomial
/// kMaxX in float: the weight is 0 from it on.
constexpr float maxX() { return static_cast<float>(kMaxX); }
/// −log₂e / 2: y = x·kYPerX.
inline constexpr float kYPerX = static_cast<float>(-0.72134752044448170368);
/// 2^f = Σ (ln 2)^k/k! f^k: the coefficients, k = 0 … kDegree, rounded to float.
inline constexpr std::array<float, kDegree + 1> kPow2 = [] {
    std::array<float, kDegree + 1> c{};
    double term = 1.0;
    for (int k = 0; k <= kDegree; ++k) {
        c[size_t(k)] = static_cast<float>(term);
        term *= 0.69314718055994530942 / (k + 1);
    }
    return c;
}();
/// @brief 2^f for f ∈ [−½, ½]: the polynomial by Estrin's scheme, f² and f⁴ beside the pairs
/// c_k + c_{k+1}·f, so its longest chain is 5 operations where Horner's is 12 (the far views'
/// point loop waited on it, docs/performance.md, session 38). Every step one float product or
/// sum, in this order: the vector form (point_weight-inl.h) repeats it operation for operation.
inline float pow2Fraction(float f) {
    static_assert(kDegree == 6, "Estrin's pairs below are written for degree 6");
    const float f2 = f * f, f4 = f2 * f2;
    const float a = kPow2[0] + kPow2[1] * f, b = kPow2[2] + kPow2[3] * f, c = kPow2[4] + kPow2[5] * f;
    return (a + f2 * b) + f4 * (c + f2 * kPow2[6]);
}
/// @brief Max |pointFilterWeight − exp(−x/2)| over 16 384 samples of [0, kMaxX).
double maxAbsError();
}  // namespace point_filter_weight

/// @brief The point filter's Gaussian weight exp(−x/2) at x = r²/V ∈ [0, kPointSupportSigmas²);
/// 0 for x ≥ point_filter_weight::kMaxX or NaN. A pure function: nothing to set up or pass.
/// No table and no gather: exp(−x/2) = 2^y with y = x·(−log₂e/2), split into n = round(y) and
/// f = y − n ∈ [−½, ½], so 2^y = 2^n·2^f, with 2^f its Taylor polynomial to degree 6 (Estrin) and
/// 2^n an exact power of two. Every step is one float product or sum (no fused multiply-add), so
/// the scalar pointFilterWeight() and the vector one (point_weight-inl.h) give the same floats on
/// every SIMD target. Error: the series' remainder (ln 2/2)⁷/7!·2^½ < 1.7e−7 of 2^f, plus a few
/// float roundings: |weight − exp(−x/2)| < 5e−7 (PointFilter.WeightMatchesTheGaussian; 1.6e−7
/// measured). Until session 27 a 1 024-interval table with linear lookups (2.4e−6), whose two
/// gathers per vector of weights were the far views' point set-up's largest cost. (Files that
/// evaluate it in vectors are built with -ffp-contract=off, CMakeLists.txt; elsewhere the scalar
/// form is compiled for the baseline x86-64, which has no fused multiply-add to contract to.)
inline float pointFilterWeight(float x) {
    namespace pfw = point_filter_weight;
    if (!(x < pfw::maxX())) return 0.0f;
    const float y = (x > 0.0f ? x : 0.0f) * pfw::kYPerX;
    const float n = std::nearbyint(y);  // round half to even, as the vector Round
    const float f = y - n;
    const float p = pfw::pow2Fraction(f);
    return p * std::bit_cast<float>((static_cast<int>(n) + 127) << 23);
}

/// @brief The weights of one point: pixel (x0 + ix, y0 + iy) gets w[iy·nx + ix]; they sum
/// to 1 (up to float rounding). Pixels may lie outside the image: the renderer skips them
/// (energy leaving the screen is lost, never piled onto the border).
struct PointFootprint {
    int x0 = 0, y0 = 0, nx = 0, ny = 0;
    std::array<float, kPointMaxSide * kPointMaxSide> w{};
    float at(int ix, int iy) const { return w[iy * nx + ix]; }
};

/// @brief Rasterizes w for a point projected at pixel coordinate @p x with filter variance
/// @p variance (px², from pointFilterVariance): the pixels whose centres lie strictly
/// within r_s = min(3√V, 3.5) of @p x, weights exp(−r²/2V) (pointFilterWeight), renormalised
/// to sum to 1. A non-finite @p x gives nx = ny = 0. The oracle of PointSetup.
PointFootprint rasterizePoint(const PixelCoord& x, double variance);

/// @brief A point's filter set up once, at projection, so that each screen tile it touches
/// evaluates only its own pixels (the compositor; rasterizePoint per tile recomputed the
/// whole footprint and its sum for every tile). At pixel (x, y) of `box`, with the float
/// offsets dx = x + ½ − centre.x, dy = y + ½ − centre.y (PointSetup::offset):
///     w = (dx² + dy² < radius2 ? weight(dx²·invVariance) · weight(dy²·invVariance) : 0) · norm
/// — the same float operations as rasterizePoint, so the same weights bit for bit
/// (PointFilter.SetupMatchesTheFootprint). The fallback footprint (a single pixel, weight 1)
/// has invVariance 0, radius2 +∞ and norm 1.
struct PointSetup {
    int x0 = 0, y0 = 0, nx = 0, ny = 0;  ///< the footprint's pixels, as PointFootprint (not clamped)
    float invVariance = 0.f;           ///< 1/V
    float radius2 = 0.f;               ///< r_s²: pixel centres strictly within it
    float norm = 0.f;                  ///< 1 / (the weights' sum over the footprint)
    bool empty() const { return nx <= 0 || ny <= 0; }
    /// The float offset of pixel index @p i's centre from the coordinate @p c (x or y):
    /// (i + ½) − c rounded once, as rasterizePoint's double difference rounded to float is
    /// (the difference of a pixel centre and a float is exact in double at image coordinates).
    static float offset(int i, float c) { return (float(i) + 0.5f) - c; }
};

/// @brief The PointSetup of a point at @p x (the float centre the compositor uses) with
/// filter variance @p variance (the float it stores): rasterizePoint's footprint and sum.
PointSetup setupPoint(const PixelCoord& x, double variance);

/// @brief setupPoint's sum with Google Highway (pointfilter/point_setup.cpp, runtime dispatch):
/// the weights of both axes in one vector (one PointWeight), the products and the circle row by row
/// in vectors, each lane a column's sum (sumColumnsPairwise's order). For a float centre (what the renderer stores)
/// the same PointSetup bit for bit (PointFilter.VectorSetupEqualsTheScalarSetup).
PointSetup setupPointVector(const PixelCoord& x, double variance);

/// @brief The footprint's weights summed in the one order every setup uses: each column down
/// its rows (@p columns[ix] = Σ over iy in order, a weight outside the circle or a column past
/// nx adding +0), then the eight columns pairwise. A vector accumulates the columns in its lanes
/// with no dependency between them, where a row-by-row sum was 49 dependent additions.
inline float sumColumnsPairwise(const float* columns) {
    return ((columns[0] + columns[1]) + (columns[2] + columns[3])) + ((columns[4] + columns[5]) + (columns[6] + columns[7]));
}
inline constexpr int kPointSumColumns = 8;  ///< ≥ kPointMaxSide: the columns sumColumnsPairwise adds
static_assert(kPointMaxSide <= kPointSumColumns);

/// setupPoint's parts before and after the sum (shared by the scalar and the vector setup):
/// the footprint's box, 1/V and r_s² (false: nothing to draw); then norm, or the one-pixel fallback.
bool pointSetupBox(const PixelCoord& x, double variance, PointSetup& s, float& invV, float& rs2);
void finishPointSetup(PointSetup& s, const PixelCoord& x, float sum, float invV, float rs2);

/// @brief One weight of @p s at pixel (@p x, @p y) of its box, for a point centred at
/// (@p cx, @p cy): the scalar form of what the compositor evaluates per tile.
inline float pointWeight(const PointSetup& s, float cx, float cy, int x, int y) {
    const float dx = PointSetup::offset(x, cx), dy = PointSetup::offset(y, cy);
    const float dy2 = dy * dy;
    const float w =
        dx * dx + dy2 < s.radius2 ? pointFilterWeight(dx * dx * s.invVariance) * pointFilterWeight(dy2 * s.invVariance) : 0.0f;
    return w * s.norm;
}

}  // namespace vdbsplat
