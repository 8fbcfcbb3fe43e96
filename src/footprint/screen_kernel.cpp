// footprint/screen_kernel.cpp — EWA widening of the exact ellipse (DESIGN §4; Zwicker
// et al. 2001, V + V_h) and the splat's per-pixel optical depth (see screen_kernel.h).
#include "footprint/screen_kernel.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "footprint/kernel.h"

namespace vdbsplat {

namespace {
/// R_u · diag(x, y) · R_uᵀ for the orthonormal frame (u, u⊥).
glm::dmat2 inFrame(const glm::dvec2& u, double x, double y) {
    const glm::dvec2 v(-u.y, u.x);
    return x * glm::outerProduct(u, u) + y * glm::outerProduct(v, v);
}
}  // namespace

ScreenKernel makeScreenKernel(const SphereProjection& e, double prefilterVariance, const KernelShape& kernel) {
    if (!e.isEllipse())
        throw std::invalid_argument(std::string("makeScreenKernel: sphere is '") + sphereClassName(e.kind) +
                                    "', not an ellipse (use the halfRayFootprint fallback)");
    // V = R_u diag((a s_g/R)², (b s_g/R)²) R_uᵀ; V' = V + V_h I has the same eigenvectors.
    const double widen = supportWidening(kernel, prefilterVariance);
    ScreenKernel k;
    k.centre = e.centre;
    k.u = e.u;
    k.aGeom = e.a, k.bGeom = e.b;
    k.a = std::sqrt(e.a * e.a + widen);
    k.b = std::sqrt(e.b * e.b + widen);
    const double invA = 1.0 / k.a, invB = 1.0 / k.b;  // (mirrored by the lane projection)
    k.conic = inFrame(e.u, invA * invA, invB * invB);
    k.amplitude = (e.a * invA) * (e.b * invB);  // √(det V / det V')
    k.sinAlpha = e.sinAlpha;
    k.pullback = inFrame(e.u, e.a * invA, e.b * invB);
    const glm::dvec2 v(-e.u.y, e.u.x);
    const glm::dvec2 half(std::sqrt(k.a * k.a * e.u.x * e.u.x + k.b * k.b * v.x * v.x),
                          std::sqrt(k.a * k.a * e.u.y * e.u.y + k.b * k.b * v.y * v.y));
    k.bounds = {k.centre - half, k.centre + half};
    return k;
}

SplatShader makeSplatShader(const ScreenKernel& k, const Tables& tables, double sigma, double h) {
    SplatShader s;
    s.row = tables.reindex.row(k.alpha());
    s.footprint = &tables.footprint;
    s.scale = static_cast<float>(sigma * h * k.amplitude);
    return s;
}

double splatDeposit(const ScreenKernel& k, const SplatShader& shader, const PixelCoord& p) {
    return shader.depositAtIndex2(static_cast<float>(k.index2(p)));
}

double exactIndexD2(const ScreenKernel& k, const SphereProjection& e, const PixelCoord& p) {
    if (!(k.index2(p) < 1.0)) return std::numeric_limits<double>::infinity();
    return exactRayDistance2(e, k.centre + k.pullback * (p - k.centre));
}

ExactIndexMap exactIndexMapOf(const glm::dvec3& u0, const glm::dvec3& ux, const glm::dvec3& uy, double kappa) {
    const double inv = 1.0 / kappa;
    ExactIndexMap m;
    m.w0 = float(glm::dot(u0, u0) * inv);
    m.wx = float(2.0 * glm::dot(u0, ux) * inv), m.wy = float(2.0 * glm::dot(u0, uy) * inv);
    m.wxx = float(glm::dot(ux, ux) * inv), m.wxy = float(2.0 * glm::dot(ux, uy) * inv), m.wyy = float(glm::dot(uy, uy) * inv);
    return m;
}

ExactIndexMap makeExactIndexMap(const ScreenKernel& k, const SphereProjection& e, const PixelCoord& origin) {
    // p' = k.centre + S·(p − k.centre) = [k.centre + S·(origin − k.centre)] + S·δ, and
    // pixelRay(p') = ((p'.x − pp.x)·(1/f), −(p'.y − pp.y)·(1/f), 1) is affine in p'. The lane
    // projection mirrors these operations.
    const double invF = 1.0 / e.f;
    const glm::dvec3 v0 = pixelRay(e, k.centre + k.pullback * (origin - k.centre));
    const glm::dvec3 vx(k.pullback[0].x * invF, -k.pullback[0].y * invF, 0.0);  // S·(1, 0) = column 0
    const glm::dvec3 vy(k.pullback[1].x * invF, -k.pullback[1].y * invF, 0.0);
    // κ = |v_c|²·(1 − d²(v_c)) = |v_c|² − |c × v_c|²/r² at the centre (i² = 0), pulled back to itself.
    const glm::dvec3 vc = pixelRay(e, k.centre), A = glm::cross(e.c, vc);
    const double kappa = glm::dot(vc, vc) - glm::dot(A, A) * (1.0 / (e.r * e.r));
    return exactIndexMapOf(v0, vx, vy, kappa);
}

double splatDepositExact(const ScreenKernel& k, const SphereProjection& e, double sigma, double h,
                         const PixelCoord& p, const KernelShape& kernel) {
    const double d2 = exactIndexD2(k, e, p);
    if (!(d2 < 1.0)) return 0.0;
    return sigma * h * kernel.footprint(std::sqrt(d2) * kernel.radius()) * k.amplitude;
}

}  // namespace vdbsplat
