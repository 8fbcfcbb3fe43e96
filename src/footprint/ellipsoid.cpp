// footprint/ellipsoid.cpp — exact projection of a kernel ellipsoid (see ellipsoid.h).
#include "footprint/ellipsoid.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "footprint/kernel.h"

namespace vdbsplat {

namespace {

constexpr double kR = Kernel::kRadius;

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// [c]ₓ: the matrix with [c]ₓ·v = c × v (GLM: columns).
glm::dmat3 crossMatrix(const glm::dvec3& c) {
    return glm::dmat3(glm::dvec3(0.0, c.z, -c.y), glm::dvec3(-c.z, 0.0, c.x), glm::dvec3(c.y, -c.x, 0.0));
}

/// Fills the ellipse fields of @p s from the pixel-space conic (p − centre)ᵀ Q (p − centre) ≤ 1
/// (Q symmetric positive definite): axes from its eigen-decomposition, as fillEllipse does for spheres.
void fillFromConic(SphereProjection& s, const PixelCoord& centre, double qxx, double qxy, double qyy) {
    const double mean = 0.5 * (qxx + qyy), dev = std::hypot(0.5 * (qxx - qyy), qxy);
    const double small = mean - dev, large = mean + dev;  // eigenvalues: 1/a², 1/b²
    glm::dvec2 u = std::abs(qxy) > 1e-300 ? glm::dvec2(small - qyy, qxy) : (qxx <= qyy ? glm::dvec2(1, 0) : glm::dvec2(0, 1));
    u = glm::normalize(u);
    s.centre = centre;
    s.u = u;
    s.a = 1.0 / std::sqrt(small);
    s.b = 1.0 / std::sqrt(large);
    const glm::dvec2 v(-u.y, u.x);
    const glm::dvec2 half(std::sqrt(s.a * s.a * u.x * u.x + s.b * s.b * v.x * v.x),
                          std::sqrt(s.a * s.a * u.y * u.y + s.b * s.b * v.y * v.y));
    s.bounds = {s.centre - half, s.centre + half};
    s.toUnit = glm::transpose(glm::dmat2(u / s.a, v / s.b));
}

/// The silhouette conic of an ellipsoid in front of the eye plane; false when it is not a
/// proper ellipse (numerically degenerate): the caller then takes the half-ray fallback.
bool silhouette(const VoxelShape& shape, const ViewPoint& c, SphereProjection& s) {
    // Inside ⟺ vᵀ C v ≥ 0 with C = R² M⁻ᵀM⁻¹ − [c]ₓᵀ M Mᵀ [c]ₓ / det²M (ellipsoid.h).
    const glm::dmat3 cx = crossMatrix(c);
    const glm::dmat3 C = kR * kR * (glm::transpose(shape.N) * shape.N) -
                         (glm::transpose(cx) * (shape.M * glm::transpose(shape.M)) * cx) / (shape.volume * shape.volume);
    // v = (X, Y, 1): Xᵀ P X + 2 qᵀX + s ≥ 0 (GLM C[col][row]; C is symmetric).
    const double pxx = C[0][0], pxy = 0.5 * (C[1][0] + C[0][1]), pyy = C[1][1];
    const glm::dvec2 q(0.5 * (C[2][0] + C[0][2]), 0.5 * (C[2][1] + C[1][2]));
    const double det = pxx * pyy - pxy * pxy;
    if (!(pxx < 0.0 && det > 0.0)) return false;  // −P must be positive definite
    const glm::dvec2 X0(-(pyy * q.x - pxy * q.y) / det, -(-pxy * q.x + pxx * q.y) / det);  // −P⁻¹q
    const double k = C[2][2] + glm::dot(q, X0);
    if (!(k > 0.0) || !std::isfinite(k)) return false;
    // (X − X0)ᵀ(−P/k)(X − X0) ≤ 1, X = ((p.x − pp.x)/f, −(p.y − pp.y)/f): in pixels Q = F(−P/k)F, F = diag(1/f, −1/f).
    const double f2 = s.f * s.f;
    const double qxx = -pxx / (k * f2), qxy = pxy / (k * f2), qyy = -pyy / (k * f2);
    if (!(qxx > 0.0 && qyy > 0.0 && qxx * qyy - qxy * qxy > 0.0)) return false;
    fillFromConic(s, s.principal + PixelCoord(s.f * X0.x, -s.f * X0.y), qxx, qxy, qyy);
    return std::isfinite(s.a) && std::isfinite(s.b) && s.b > 0.0;
}

}  // namespace

glm::dvec3 singularValues(const glm::dmat3& m) {
    const glm::dmat3 S = glm::transpose(m) * m;  // eigenvalues σ²
    const double p1 = S[0][1] * S[0][1] + S[0][2] * S[0][2] + S[1][2] * S[1][2];
    const double q = (S[0][0] + S[1][1] + S[2][2]) / 3.0;
    const double p2 = (S[0][0] - q) * (S[0][0] - q) + (S[1][1] - q) * (S[1][1] - q) + (S[2][2] - q) * (S[2][2] - q) + 2.0 * p1;
    const double p = std::sqrt(p2 / 6.0);
    glm::dvec3 e(q);
    if (p > 1e-300 * std::max(1.0, q)) {
        const glm::dmat3 B = (S - q * glm::dmat3(1.0)) / p;
        const double r = std::clamp(glm::determinant(B) / 2.0, -1.0, 1.0);
        const double phi = std::acos(r) / 3.0;
        e.x = q + 2.0 * p * std::cos(phi);
        e.z = q + 2.0 * p * std::cos(phi + 2.0 * std::numbers::pi / 3.0);
        e.y = 3.0 * q - e.x - e.z;
    }
    return glm::sqrt(glm::max(e, glm::dvec3(0.0)));
}

VoxelShape VoxelShape::of(const glm::dmat3& m) {
    VoxelShape k;
    k.M = m;
    k.N = glm::inverse(m);
    k.volume = std::abs(glm::determinant(m));
    k.h = std::cbrt(k.volume);
    const glm::dvec3 s = singularValues(m);
    k.sMax = s.x, k.sMin = s.z;
    k.sphere = k.sMax - k.sMin <= 1e-9 * k.sMax;
    return k;
}

EllipsoidProjection projectEllipsoid(const VoxelShape& shape, const ViewPoint& c, double f, const PixelCoord& principal) {
    EllipsoidProjection out;
    SphereProjection& s = out.ellipse;
    if (!finite3(c) || !(f > 0.0) || !std::isfinite(f) || !std::isfinite(principal.x) || !std::isfinite(principal.y))
        return out;
    s.c = c, s.f = f, s.principal = principal;
    s.r = kR * shape.sMax;  // the bounding sphere (conservative boxes; not the kernel)
    s.D = glm::length(c);
    s.rho = std::hypot(c.x, c.y);
    s.sinAlpha = std::min(1.0, s.r / std::max(s.D, 1e-300));
    const double nc = glm::length(shape.N * c);
    out.lengthScale = nc > 0.0 ? s.D / nc : 0.0;
    const glm::dvec3 zRow(shape.M[0][2], shape.M[1][2], shape.M[2][2]);  // view z of M·u is zRow·u
    const double zExtent = kR * glm::length(zRow);
    if (c.z < -zExtent) return out;  // Behind
    if (nc <= kR) out.kind = SphereClass::EyeInside;
    else if (c.z <= zExtent * (1.0 + 1e-9) || !silhouette(shape, c, s)) out.kind = SphereClass::Straddles;
    else out.kind = SphereClass::Ellipse;
    s.kind = out.kind;
    if (out.kind != SphereClass::Ellipse) s.bounds = projectSphere(c, s.r, f, principal).bounds;
    return out;
}

double ellipsoidRayDistance2(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v) {
    const glm::dvec3 w = glm::transpose(shape.M) * glm::cross(c, v) / shape.volume, vi = shape.N * v;
    return glm::dot(w, w) / (glm::dot(vi, vi) * kR * kR);
}

bool rayHitsEllipsoid(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v) {
    const glm::dvec3 nv = shape.N * v, nc = shape.N * c;  // Q = NᵀN: vᵀQc = (Nv)·(Nc)
    const double b = glm::dot(nv, nc), a = glm::dot(nv, nv), k = glm::dot(nc, nc) - kR * kR;
    return b * b - a * k >= 0.0;
}

ExactIndexMap makeEllipsoidIndexMap(const ScreenKernel& k, const EllipsoidProjection& e, const VoxelShape& shape,
                                    const PixelCoord& origin) {
    const SphereProjection& s = e.ellipse;
    // The view rays of the pulled-back pixels, affine in δ (as makeExactIndexMap), then into
    // index space, where the kernel is a ball: d² − 1 and i² − 1 are proportional there too
    // (screen_kernel.h), with κ = |M⁻¹v_c|²·(1 − d²(v_c)) at the ellipse's centre.
    const glm::dvec3 v0 = pixelRay(s, k.centre + k.pullback * (origin - k.centre));
    const glm::dvec3 vx(k.pullback[0].x / s.f, -k.pullback[0].y / s.f, 0.0);
    const glm::dvec3 vy(k.pullback[1].x / s.f, -k.pullback[1].y / s.f, 0.0);
    const glm::dvec3 vc = pixelRay(s, k.centre), nc = shape.N * vc;
    const double kappa = glm::dot(nc, nc) * (1.0 - ellipsoidRayDistance2(shape, s.c, vc));
    return exactIndexMapOf(shape.N * v0, shape.N * vx, shape.N * vy, kappa);
}

double ellipsoidHalfRayDeposit(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v) {
    const glm::dvec3 vi = shape.N * glm::normalize(v);  // index length per world length along v
    const double perWorld = glm::length(vi);
    if (!(perWorld > 0.0)) return 0.0;
    const glm::dvec3 e = vi / perWorld, nc = shape.N * c;  // unit index direction; centre − eye in index space
    const double tStar = glm::dot(nc, e);                 // closest point's parameter (index units)
    const double rho = glm::length(glm::cross(nc, e));
    // The ray starts at the eye, −t* from the closest point; world length per index length 1/perWorld.
    return Kernel::segmentIntegral(rho, -tStar, kR) / (perWorld * shape.h);
}

}  // namespace vdbsplat
