// footprint/screen_kernel.h — the EWA-filtered screen kernel of one splat (DESIGN §4).
// Owns: widening the exact projected ellipse (footprint/ellipse.h) by the screen
// low-pass (Zwicker et al. 2001, EWA volume splatting: resampling filter = footprint ⊗ low-pass, with
// V_h = kPrefilterVariance·I, footprint/prefilter.h), its conic, bounds and amplitude,
// and the per-pixel optical depth of the splat on the table path and the exact path.
//
// The footprint's screen variance is the ellipse's axes scaled by s_g/R:
//     V  = R_u · diag((a·s_g/R)², (b·s_g/R)²) · R_uᵀ,       V' = V + V_h
// Adding a multiple of I keeps V's eigenvectors, so the support ellipse keeps the
// axes u, u⊥ with semi-axes a' = √(a² + (R/s_g)²·V_h), b' likewise (std × R/s_g), and
//     conic Q = R_u · diag(1/a'², 1/b'²) · R_uᵀ,   i² = (p − centre)ᵀ Q (p − centre),
//     amplitude = √(det V / det V') = a·b / (a'·b')   (the deposit's total is unchanged,
//     as in gsplat's antialiased mode).
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

#include "camera/camera.h"
#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/prefilter.h"
#include "footprint/pixel_box.h"
#include "footprint/tables.h"

namespace vdbsplat {

/// @brief The widened (low-pass filtered) support ellipse of one splat.
struct ScreenKernel {
    PixelCoord centre{0.0};    ///< the exact ellipse's centre (DESIGN §2)
    glm::dvec2 u{1.0, 0.0};    ///< major direction (pixel space)
    double a = 0.0, b = 0.0;   ///< support semi-axes after widening (pixels), a' and b'
    double aGeom = 0.0, bGeom = 0.0;  ///< the exact ellipse's semi-axes before widening
    glm::dmat2 conic{0.0};     ///< Q: i² = (p − centre)ᵀ Q (p − centre), ≤ 1 on the support
    double amplitude = 0.0;    ///< √(det V / det(V + V_h)) ∈ (0, 1]
    double sinAlpha = 0.0;     ///< sin α of the sphere (sin²α picks the polynomial row)
    /// @brief The half cone angle α (the table path's reindex row), asin on demand.
    double alpha() const { return std::asin(std::clamp(sinAlpha, 0.0, 1.0)); }
    PixelBox bounds;           ///< exact bounding box of the support ellipse
    /// S: maps p − centre on the widened support to the geometric ellipse,
    /// S = R_u diag(a/a', b/b') R_uᵀ (used by the exact path).
    glm::dmat2 pullback{1.0};

    /// @brief i² at pixel coordinate @p p.
    double index2(const PixelCoord& p) const {
        const glm::dvec2 x = p - centre;
        return glm::dot(x, conic * x);
    }
};

/// @brief What the low-pass of variance @p prefilterVariance (px²) adds to the squares of the
/// kernel's support semi-axes: (R/s_g)²·max(V, 0), so a' = √(a² + w) (makeScreenKernel).
inline double supportWideningPerVariance(const KernelShape& kernel) {
    const double toSupport = kernel.radius() / kernel.sigma();  // std → support semi-axis
    return toSupport * toSupport;
}
inline double supportWidening(const KernelShape& kernel, double prefilterVariance) {
    return supportWideningPerVariance(kernel) * std::max(prefilterVariance, 0.0);
}

/// @brief The EWA screen kernel of the Ellipse @p e with low-pass variance
/// @p prefilterVariance (px²; 0 gives the unfiltered exact ellipse, amplitude 1).
/// @throw std::invalid_argument when @p e is not an Ellipse (see projectSphere's fallback).
/// @p kernel: its R/s_g converts standard deviations to the support (the standard kernel by default).
ScreenKernel makeScreenKernel(const SphereProjection& e, double prefilterVariance = kPrefilterVariance,
                              const KernelShape& kernel = KernelShape::standard());

/// @brief Per-pixel optical depth of one splat on the TABLE path, prepared once per splat:
///     τ(p) = σ_k · h · F(d) · amplitude,   d² = reindex(i², α) (2D table), F from the 1D table.
/// Holds pointers into @p tables, which must outlive it.
struct SplatShader {
    ReindexTable::Row row;
    const FootprintTable* footprint = nullptr;
    float scale = 0.0f;  ///< σ_k · h · amplitude

    /// @brief τ at squared index @p i2 (0 for i2 ≥ 1).
    float depositAtIndex2(float i2) const {
        if (!(i2 < 1.0f)) return 0.0f;
        return scale * footprint->lookupD2(row.d2(i2));
    }
    /// @brief τ at squared normalised distance @p d2 (from exactIndexD2; 0 for d2 ≥ 1).
    float depositAtD2(float d2) const { return scale * footprint->lookupD2(d2); }
};

/// @brief The table-path shader of @p k for a voxel of extinction @p sigma (per world
/// unit) and size @p h (world units).
SplatShader makeSplatShader(const ScreenKernel& k, const Tables& tables, double sigma, double h);

/// @brief τ at pixel coordinate @p p on the table path (slow convenience: index2 + shader).
double splatDeposit(const ScreenKernel& k, const SplatShader& shader, const PixelCoord& p);

/// @brief The exact d² for pixel @p p of the widened kernel @p k of sphere @p e: the pixel
/// pulled back to the geometric ellipse, p' = centre + S·(p − centre), then
/// exactRayDistance2(e, p'). Returns +infinity outside the support (i² ≥ 1). With
/// SplatShader::depositAtD2 this is the fast exact path: it removes the affine-index
/// error off-axis (which grows like tanθ·tanα, see docs/footprint.md) at about the cost
/// of the table path.
double exactIndexD2(const ScreenKernel& k, const SphereProjection& e, const PixelCoord& p);

/// @brief exactIndexD2 from the affine index, for hot loops (--footprint auto; docs/footprint.md,
/// "The exact index from the affine one"). The kernel's silhouette is the conic's ellipse, so
/// with v the ray through the pulled-back pixel, d² − 1 = (|c × v|² − r²|v|²)/(r²|v|²) and i² − 1
/// are two quadratics of the pixel with the same zero set: proportional. At the ellipse's centre
/// (i² = 0, ray v_c) the factor is κ = |v_c|²·(1 − d²(v_c)), so
///     d² = 1 − (1 − i²) / w(δ),   w(δ) = |v(δ)|² / κ,
/// and, v being affine in δ = pixel − origin (pixelRay and the pullback are), w is a quadratic
/// in δ: six numbers per splat instead of the 19 of the ray and c × v, and per pixel two FMAs
/// (a row's part set up once), a division and two subtractions on top of the i² the loop has.
/// An ellipsoid's kernel is a ball in index space: v there is M⁻¹v (makeEllipsoidIndexMap).
/// w is formed in double and rounded to float; with the float i² of the compositor's conic,
/// d² stays within ~2e−7 of exactIndexD2 (ScreenKernel.ExactIndexMapMatchesExactIndexD2).
/// It does not test the support: callers use the conic (i² < 1, which gives d² < 1) as the
/// table path does.
struct ExactIndexMap {
    float w0 = 0.f, wx = 0.f, wy = 0.f;     ///< w(δ) = w0 + wx·δx + wy·δy
    float wxx = 0.f, wxy = 0.f, wyy = 0.f;  ///<        + wxx·δx² + wxy·δx·δy + wyy·δy²

    float w(float dx, float dy) const { return w0 + dx * (wx + wxx * dx) + dy * (wy + wxy * dx + wyy * dy); }
    /// d² at offsets (@p dx, @p dy) from the origin, where the conic's index is @p i2 (clamped at
    /// 0: near the centre ray the difference of two numbers close to 1 can round below it).
    float d2(float i2, float dx, float dy) const { return std::max(0.f, 1.f - (1.f - i2) / w(dx, dy)); }
    bool operator==(const ExactIndexMap&) const = default;
};

/// @brief The ExactIndexMap of the rays u(δ) = @p u0 + δx·@p ux + δy·@p uy through the pulled-back
/// pixels, in the space where the kernel is a ball, and @p kappa = κ (see ExactIndexMap): the
/// coefficients of |u(δ)|²/κ, each dot product (glm's order) times 1/κ (the lane projection
/// mirrors these operations).
ExactIndexMap exactIndexMapOf(const glm::dvec3& u0, const glm::dvec3& ux, const glm::dvec3& uy, double kappa);

/// @brief The ExactIndexMap of kernel @p k of Ellipse @p e, with δ measured from @p origin.
ExactIndexMap makeExactIndexMap(const ScreenKernel& k, const SphereProjection& e, const PixelCoord& origin);

/// @brief τ at @p p on the EXACT path. "Exact" for the widened kernel means: pull p back
/// to the unwidened geometric ellipse, p' = centre + S·(p − centre) (same unit-disk
/// coordinates), and use the exact ray–centre distance of p' instead of the affine index
/// and the reindex table: τ = σ·h·Kernel::footprint(R·exactRayDistance(e, p'))·amplitude.
/// Without widening (V_h = 0) this is the exact per-pixel footprint of the sphere; it
/// differs from the table path only by the affine-index approximation off-axis and the
/// tables' interpolation error (DESIGN §3), which is what it is there to measure.
/// Uses the closed form Kernel::footprint (erf): a measuring tool, not for the hot loop.
double splatDepositExact(const ScreenKernel& k, const SphereProjection& e, double sigma, double h,
                         const PixelCoord& p, const KernelShape& kernel = KernelShape::standard());

}  // namespace vdbsplat
