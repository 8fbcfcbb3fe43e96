// footprint/ellipse.cpp — exact projection of a kernel sphere (DESIGN §2, Yuan et al.
// 2003 Appendix A) and the brute-force ray–sphere oracle (see ellipse.h).
#include "footprint/ellipse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "footprint/kernel.h"

namespace vdbsplat {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinDen = 1e-12;  // den below this: treated as Straddles (a, b would overflow)

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Conservative range of x/z for x ∈ [x0, x1], z ∈ [z0, z1], 0 ≤ z0, 0 < z1 (interval division).
void ratioRange(double x0, double x1, double z0, double z1, double& lo, double& hi) {
    lo = x0 >= 0.0 ? x0 / z1 : (z0 > 0.0 ? x0 / z0 : -kInf);
    hi = x1 <= 0.0 ? x1 / z1 : (z0 > 0.0 ? x1 / z0 : kInf);
}

/// A conservative pixel box of the visible part (z > 0) of the sphere's bounding cube.
PixelBox sphereBounds(const SphereProjection& s) {
    const double z1 = s.c.z + s.r, z0 = std::max(s.c.z - s.r, 0.0);
    if (z1 <= 0.0) return {};
    double qx0, qx1, qy0, qy1;
    ratioRange(s.c.x - s.r, s.c.x + s.r, z0, z1, qx0, qx1);
    ratioRange(s.c.y - s.r, s.c.y + s.r, z0, z1, qy0, qy1);
    // pixel = principal + f·(x/z, −y/z): y flips, so y bounds swap.
    return {{s.principal.x + s.f * qx0, s.principal.y - s.f * qy1},
            {s.principal.x + s.f * qx1, s.principal.y - s.f * qy0}};
}

/// Fills centre, u, a, b, bounds, toUnit for an Ellipse (DESIGN §2, with
/// den = cos²θ − sin²α = (z² − r²)/D² substituted for accuracy):
///   a = f·r·√(D² − r²)/(z² − r²), b = f·r/√(z² − r²), |centre − principal| = f·ρ·z/(z² − r²).
void fillEllipse(SphereProjection& s) {
    const double z = s.c.z, r2 = s.r * s.r;
    const double rhoXY = s.rho;                      // D·sinθ
    const double q = z * z - r2;                     // D²·den
    // Reciprocals once (1/ρ, 1/q), products after: the lane projection (render/project_vector.cpp)
    // mirrors these operations, and its double divisions were what bounded it.
    const double invRho = rhoXY > 0.0 ? 1.0 / rhoXY : 0.0, invQ = 1.0 / q;
    s.u = rhoXY > 0.0 ? glm::dvec2(s.c.x * invRho, -s.c.y * invRho) : glm::dvec2(1.0, 0.0);  // y flip
    s.centre = s.principal + s.u * (s.f * rhoXY * z * invQ);
    s.a = s.f * s.r * std::sqrt(s.D * s.D - r2) * invQ;
    s.b = s.f * s.r / std::sqrt(q);
    const glm::dvec2 v(-s.u.y, s.u.x);
    const glm::dvec2 half(std::sqrt(s.a * s.a * s.u.x * s.u.x + s.b * s.b * v.x * v.x),
                          std::sqrt(s.a * s.a * s.u.y * s.u.y + s.b * s.b * v.y * v.y));
    s.bounds = {s.centre - half, s.centre + half};
    // Rows u/a and u⊥/b; GLM is column-major, so build the transpose.
    s.toUnit = glm::transpose(glm::dmat2(s.u / s.a, v / s.b));
}
}  // namespace

const char* sphereClassName(SphereClass k) {
    switch (k) {
        case SphereClass::Ellipse: return "ellipse";
        case SphereClass::EyeInside: return "eye-inside";
        case SphereClass::Straddles: return "straddles";
        case SphereClass::Behind: return "behind";
    }
    return "?";
}

SphereProjection projectSphere(const ViewPoint& c, double r, double f, const PixelCoord& principal) {
    SphereProjection s;
    if (!finite3(c) || !(r > 0.0) || !std::isfinite(r) || !(f > 0.0) || !std::isfinite(f) ||
        !std::isfinite(principal.x) || !std::isfinite(principal.y))
        return s;  // Behind: culled, all fields zero
    s.c = c, s.r = r, s.f = f, s.principal = principal;
    s.D = glm::length(c);
    s.rho = std::sqrt(c.x * c.x + c.y * c.y);  // no overflow for view coordinates (hypot is a slow libm call)
    if (s.D <= r) {
        s.kind = SphereClass::EyeInside;
        s.sinAlpha = 1.0;
    } else {
        s.sinAlpha = r / s.D;  // α itself (asin) only on demand: alpha()
        const double den = (c.z * c.z - r * r) / (s.D * s.D);  // cos²θ − sin²α
        if (c.z < -r) s.kind = SphereClass::Behind;
        else if (c.z <= r || den < kMinDen) s.kind = SphereClass::Straddles;
        else s.kind = SphereClass::Ellipse;
    }
    if (s.kind == SphereClass::Ellipse) fillEllipse(s);
    else if (s.kind != SphereClass::Behind) s.bounds = sphereBounds(s);
    return s;
}

SphereProjection projectSphere(const Camera& camera, const ViewPoint& c, double r) {
    return projectSphere(c, r, camera.focal(), camera.principal());
}

double SphereProjection::index2(const PixelCoord& p) const {
    if (kind != SphereClass::Ellipse) return std::numeric_limits<double>::infinity();
    const glm::dvec2 w = toUnit * (p - centre);
    return glm::dot(w, w);
}

double SphereProjection::index(const PixelCoord& p) const { return std::sqrt(index2(p)); }

double SphereProjection::alpha() const {
    return kind == SphereClass::EyeInside ? std::numbers::pi / 2.0 : std::asin(std::clamp(sinAlpha, 0.0, 1.0));
}

double SphereProjection::theta() const { return D > 0.0 ? std::atan2(rho, c.z) : 0.0; }

double SphereProjection::affineIndexError() const {
    if (kind != SphereClass::Ellipse) return std::numeric_limits<double>::infinity();
    // tanθ·tanα with tanθ = ρ/z and tanα = r/√(D² − r²) (an Ellipse has z > r > 0 and D > r).
    return (rho * r) / (c.z * std::sqrt((D - r) * (D + r)));
}

glm::dvec3 pixelRay(const SphereProjection& s, const PixelCoord& p) {
    const double invF = 1.0 / s.f;  // (as makeExactIndexMap and the lane projection, which mirrors it)
    return {(p.x - s.principal.x) * invF, -(p.y - s.principal.y) * invF, 1.0};
}

bool rayHitsSphere(const SphereProjection& s, const PixelCoord& p) {
    if (!(s.r > 0.0)) return false;
    const glm::dvec3 v = pixelRay(s, p);
    return glm::length(glm::cross(s.c, v)) <= s.r * glm::length(v);
}

double exactRayDistance(const SphereProjection& s, const PixelCoord& p) {
    if (!(s.r > 0.0)) return std::numeric_limits<double>::infinity();
    const glm::dvec3 v = pixelRay(s, p);
    return glm::length(glm::cross(s.c, v)) / (glm::length(v) * s.r);
}

double exactRayDistance2(const SphereProjection& s, const PixelCoord& p) {
    if (!(s.r > 0.0)) return std::numeric_limits<double>::infinity();
    const glm::dvec3 v = pixelRay(s, p);
    const glm::dvec3 w = glm::cross(s.c, v);
    return glm::dot(w, w) / (glm::dot(v, v) * s.r * s.r);
}

double halfRayFootprint(const SphereProjection& s, const PixelCoord& p, const KernelShape& kernel) {
    if (!(s.r > 0.0) || s.kind == SphereClass::Behind) return 0.0;
    const glm::dvec3 v = glm::normalize(pixelRay(s, p));
    const double toVoxel = kernel.radius() / s.r;  // r world units = R voxels
    const double tStar = glm::dot(s.c, v);         // ray parameter of the closest point
    const double rho = glm::length(glm::cross(s.c, v));
    // The ray starts at the eye (t = 0), i.e. at −t* from the closest point.
    return kernel.segmentIntegral(rho * toVoxel, -tStar * toVoxel, kernel.radius());
}

}  // namespace vdbsplat
