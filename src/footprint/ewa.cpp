// footprint/ewa.cpp — Zwicker et al. 2001's affine screen kernel (see ewa.h).
#include "footprint/ewa.h"

#include <cmath>

namespace vdbsplat {

glm::dmat3 ewaJacobian(const ViewPoint& t) {
    const double l = glm::length(t);
    const double iz = 1.0 / t.z, iz2 = iz * iz;
    glm::dmat3 J(0.0);  // J[col][row]: ∂(t0/t2, t1/t2, ‖t‖)/∂t (Zwicker et al. 2001, local affine approximation)
    J[0][0] = iz, J[1][0] = 0.0, J[2][0] = -t.x * iz2;
    J[0][1] = 0.0, J[1][1] = iz, J[2][1] = -t.y * iz2;
    J[0][2] = t.x / l, J[1][2] = t.y / l, J[2][2] = t.z / l;
    return J;
}

glm::dmat3 worldToViewRotation(const Camera& camera) {
    return glm::transpose(glm::dmat3(camera.right(), camera.up(), camera.forward()));  // rows r, u, f
}

glm::dmat2 ewaRaySpaceVariance(const ViewPoint& t, const glm::dmat3& worldToView, double kernelSigmaWorld) {
    const glm::dmat3 J = ewaJacobian(t);
    const glm::dmat3 Vobj = kernelSigmaWorld * kernelSigmaWorld * glm::dmat3(1.0);  // V''_k
    const glm::dmat3 Vray = J * worldToView * Vobj * glm::transpose(worldToView) * glm::transpose(J);  // V'_k = J W V''_k Wᵀ Jᵀ
    return glm::dmat2(Vray[0][0], Vray[0][1], Vray[1][0], Vray[1][1]);  // integrated along x2: drop row and column 3
}

glm::dmat2 ewaScreenVariance(const ViewPoint& t, const glm::dmat3& worldToView, double kernelSigmaWorld,
                             double focal) {
    const glm::dmat2 S(focal, 0.0, 0.0, -focal);  // image-plane (z = 1, y up) → pixels (y down)
    return S * ewaRaySpaceVariance(t, worldToView, kernelSigmaWorld) * glm::transpose(S);
}

EwaKernel makeEwaKernel(const Camera& camera, const ViewPoint& c, double h, double kernelSigma, double kernelRadius,
                        double prefilterVariance) {
    EwaKernel k;
    if (!(c.z > 0.0)) return k;
    const glm::dmat2 sigma = ewaScreenVariance(c, worldToViewRotation(camera), kernelSigma * h, camera.focal());
    const glm::dmat2 widened = sigma + std::max(prefilterVariance, 0.0) * glm::dmat2(1.0);  // resampling filter: + V_h
    const double det = glm::determinant(sigma), detW = glm::determinant(widened);
    if (!(std::isfinite(detW) && detW > 0.0 && det > 0.0)) return k;
    k.centre = camera.project(c);
    k.variance = widened;
    const double toSupport = kernelRadius / kernelSigma;  // standard deviations → support semi-axis
    k.conic = glm::inverse(widened) / (toSupport * toSupport);
    k.amplitude = std::sqrt(det / detW);
    // The support ellipse xᵀ (Σ'·(R/s_g)²)⁻¹ x ≤ 1 spans ±(R/s_g)·√Σ'_xx in x and likewise in y.
    const glm::dvec2 half(toSupport * std::sqrt(widened[0][0]), toSupport * std::sqrt(widened[1][1]));
    k.bounds = {k.centre - half, k.centre + half};
    return k;
}

}  // namespace vdbsplat
