// footprint/ewa.h — EWA volume splatting's screen kernel (Zwicker et al. 2001, DESIGN §6).
// Owns: the local affine approximation of the perspective projection at a voxel centre (the
// Jacobian J of the ray-space map), the ray-space variance J·W·V·Wᵀ·Jᵀ with the third row and
// column dropped, the low-pass V_h added, and the resulting Gaussian splat (conic, amplitude,
// bounds) that `--mode ewa` draws for every voxel.
//
// Zwicker et al. 2001 (EWA Volume Splatting), the sections on the viewing and projective
// transformations and on the resampling filter, cited by name (the equation numbers differ
// between the 2001 paper and the 2002 journal version; docs/kernel.md §8):
//   ray space  x = m(t) = (t0/t2, t1/t2, ‖t‖)ᵀ                 (the projective mapping to ray space)
//   Jacobian   J_k = ∂m/∂t at t_k = the voxel's view-space centre (its local affine approximation)
//              ⎡1/t2   0    −t0/t2²⎤
//              ⎢ 0   1/t2   −t1/t2²⎥
//              ⎣t0/l  t1/l   t2/l  ⎦,   l = ‖t_k‖
//   V'_k = J_k W V''_k Wᵀ J_kᵀ  (the ray-space kernel): W the viewing rotation (world → view), V''_k the
//          kernel's object-space variance, here (s_g·h)²·I (world units²);
//   footprint: integrating the ray-space Gaussian along x2 drops the third row and column
//          (the 2×2 matrix V̂'_k); the EWA resampling filter: + V_h = I.
// In pixels the image-plane map is p = principal + (f·x0, −f·x1), so the 2×2 variance is
//     Σ = S·V̂'·Sᵀ,  S = diag(f, −f),      Σ' = Σ + V_h·I.
//
// Unlike hybrid (footprint/ellipse.h: the exact perspective ellipse, centred at the midpoint of
// A′B′ and not at the projection of c, plus the (i, α) reindex), EWA centres the splat at the
// projection of c and uses the affine map everywhere: exact in the limit α → 0 on the axis,
// increasingly wrong off-axis and close to the eye (measured in tests/footprint/ewa_test.cpp).
//
// Energy (DESIGN §4): the splat deposits σ·h·F(d)·amplitude with d² = (p − c')ᵀ Q (p − c'),
// Q = (s_g/R)²·Σ'⁻¹ (the support ellipse is R/s_g standard deviations), F the footprint table.
// Its screen integral is σ·h·amplitude·√det(Σ')/s_g² = σ·h·√det(Σ)/s_g², and
// √det Σ = f²·(s_g h)²·l/t2³ (det J = l/t2³), so the total is σ·h·(h f/z)²·(D/z): exactly the
// point's pointDepositTotal — Zwicker's 1/|J⁻¹| normalisation, nothing added.
#pragma once
#include <glm/glm.hpp>

#include "camera/camera.h"
#include "footprint/pixel_box.h"
#include "footprint/prefilter.h"

namespace vdbsplat {

/// @brief J_k of Zwicker et al. 2001 (the local affine approximation): the Jacobian of the ray-space map
/// m(t) = (t0/t2, t1/t2, ‖t‖) at view point @p t (t2 > 0). GLM is column-major: J[col][row].
glm::dmat3 ewaJacobian(const ViewPoint& t);

/// @brief The ray-space footprint variance V̂'_k (Zwicker et al. 2001): the upper-left 2×2 block of
/// J·W·V''·Wᵀ·Jᵀ for an isotropic object-space kernel of standard deviation @p kernelSigmaWorld,
/// with W = @p worldToView (a rotation; V'' = s²·I). Units: (image plane at z = 1)².
glm::dmat2 ewaRaySpaceVariance(const ViewPoint& t, const glm::dmat3& worldToView, double kernelSigmaWorld);

/// @brief Σ = S·V̂'·Sᵀ with S = diag(f, −f): the footprint's screen variance in px² (no low-pass).
glm::dmat2 ewaScreenVariance(const ViewPoint& t, const glm::dmat3& worldToView, double kernelSigmaWorld,
                             double focal);

/// @brief One EWA splat: the Gaussian resampling filter Σ' = Σ + V_h·I at the projection of c.
struct EwaKernel {
    PixelCoord centre{0.0};    ///< the projection of the voxel centre (the affine map's origin)
    glm::dmat2 variance{0.0};  ///< Σ' (px²)
    glm::dmat2 conic{0.0};     ///< Q = (s_g/R)²·Σ'⁻¹: i² = (p − centre)ᵀ Q (p − centre) ≤ 1 on the support
    double amplitude = 0.0;    ///< √(det Σ / det Σ'): keeps the total (the resampling filter, Σ's normalisation)
    PixelBox bounds;           ///< exact bounding box of the support ellipse
    /// @brief i² at pixel coordinate @p p.
    double index2(const PixelCoord& p) const {
        const glm::dvec2 x = p - centre;
        return glm::dot(x, conic * x);
    }
};

/// @brief The EWA splat of a voxel at view point @p c (c.z > 0) of size @p h (world units) seen by
/// @p camera, with the kernel's standard deviation s_g = @p kernelSigma and support @p kernelRadius
/// (voxel units) and low-pass @p prefilterVariance (px²; 0: none). Returns an empty-bounds kernel
/// (amplitude 0) when c.z ≤ 0 or the variance is not finite.
EwaKernel makeEwaKernel(const Camera& camera, const ViewPoint& c, double h, double kernelSigma, double kernelRadius,
                        double prefilterVariance = kPrefilterVariance);

/// @brief The camera's world → view rotation W (rows: right, up, forward).
glm::dmat3 worldToViewRotation(const Camera& camera);

}  // namespace vdbsplat
