// footprint/ellipse.h — the exact perspective projection of one kernel sphere (DESIGN §2).
// Owns: classifying a sphere (view-space centre c, radius r = R·h) against the eye
// {Ellipse, EyeInside, Straddles, Behind}; for an Ellipse its centre, major
// direction u (pixel space, y down), semi-axes a (along u) and b, the half cone
// angle α and off-axis angle θ, its pixel bounding box and the affine
// ellipse→unit-circle index i(p) (DESIGN §3; Yuan et al. 2003, Appendix A);
// the brute-force ray–sphere oracle used by tests and by the exact footprint
// path; and the documented fallback for spheres that do not project to an
// ellipse (see projectSphere()).
#pragma once
#include <glm/glm.hpp>

#include "camera/camera.h"
#include "footprint/kernel.h"
#include "footprint/pixel_box.h"

namespace vdbsplat {

/// @brief How a kernel sphere projects (DESIGN §2).
enum class SphereClass {
    Ellipse,    ///< |c.z| > r and c.z > 0: the silhouette cone cuts the image plane in an ellipse
    EyeInside,  ///< D = |c| ≤ r: the eye is inside the kernel (α undefined)
    Straddles,  ///< |c.z| ≤ r, D > r: cos²θ ≤ sin²α, the conic is a parabola/hyperbola
    Behind,     ///< c.z < −r: entirely behind the eye plane, invisible
};

/// @brief A human-readable name ("ellipse", "eye-inside", …) for messages and stats.
const char* sphereClassName(SphereClass k);

/// @brief The projection of one kernel sphere. All fields are finite for every input
/// with finite c, r > 0, f > 0 (never NaN); fields that a class does not define are 0.
struct SphereProjection {
    SphereClass kind = SphereClass::Behind;
    ViewPoint c{0.0};          ///< view-space centre of the kernel
    double r = 0.0;            ///< sphere radius (world units), r = R·h
    double f = 0.0;            ///< focal length (pixels)
    PixelCoord principal{0.0}; ///< principal point (pixels)
    double D = 0.0;            ///< |c|
    double sinAlpha = 0.0;     ///< sin α = r/D (DESIGN §2); 1 when the eye is inside
    double rho = 0.0;          ///< D·sinθ = |c.xy|, the centre's distance from the optical axis
    glm::dvec2 u{1.0, 0.0};    ///< unit major direction in pixel space (radial; (1,0) on-axis)
    PixelCoord centre{0.0};    ///< ellipse centre (NOT the projection of c)
    double a = 0.0;            ///< semi-axis along u (pixels)
    double b = 0.0;            ///< semi-axis along u⊥ = (−u.y, u.x) (pixels)
    /// Pixel bounds: exact bounding box of the ellipse; for EyeInside/Straddles a
    /// conservative (possibly infinite) box of the sphere's visible part; empty when Behind.
    PixelBox bounds;
    glm::dmat2 toUnit{0.0};    ///< affine map p − centre ↦ unit-disk coordinates (columns: GLM)

    bool isEllipse() const { return kind == SphereClass::Ellipse; }
    /// @brief Half cone angle α = asin(r/D); π/2 when the eye is inside. The hot path needs
    /// only sin α (and sin²α): the angle is computed on demand, for the table path and tests.
    double alpha() const;
    /// @brief Angle θ between c and the optical axis, atan2(ρ, c.z) (on demand, as alpha()).
    double theta() const;
    /// @brief i(p)²: squared affine index of pixel coordinate @p p, ≤ 1 inside the ellipse
    /// (DESIGN §3). +infinity for a sphere that is not an Ellipse.
    double index2(const PixelCoord& p) const;
    /// @brief i(p) = sqrt(index2(p)).
    double index(const PixelCoord& p) const;
    /// @brief tanθ·tanα: the measured max |d(i(p), α) − d_exact(p)| of the affine index over
    /// the ellipse, to within 15 % (docs/footprint.md; the footprint's error is ≈ 1.7× this,
    /// relative to its peak). 0 on the axis; +infinity for a sphere that is not an Ellipse.
    /// Closed form from the geometry, no trigonometry: tanθ = ρ/c.z, tanα = r/√(D² − r²).
    double affineIndexError() const;
};

/// @brief Projects the sphere of radius @p r centred at view point @p c through a
/// pinhole with focal length @p f pixels and principal point @p principal (DESIGN §2):
///   den = cos²θ − sin²α = (c.z² − r²)/D²,
///   centre = principal + u·f·sinθcosθ/den,  a = f·sinα·cosα/den,  b = f·sinα/√den.
/// Fallback policy for the other classes (the renderer follows it): Behind → cull;
/// EyeInside / Straddles → no ellipse, no splat kernel; draw the sphere with the exact
/// per-pixel half-ray integral halfRayFootprint() over `bounds` clamped to the image
/// (exact, never NaN; costly but such kernels lie within R·h of the eye plane, so they
/// are few). Spheres whose den < 1e−12 are treated as Straddles (no overflow).
/// @throw nothing; r ≤ 0, f ≤ 0 or non-finite input gives kind = Behind (culled).
SphereProjection projectSphere(const ViewPoint& c, double r, double f, const PixelCoord& principal);

/// @brief projectSphere() with the camera's focal length and principal point.
SphereProjection projectSphere(const Camera& camera, const ViewPoint& c, double r);

/// @brief View-space direction (z = 1) of the ray through pixel coordinate @p p.
glm::dvec3 pixelRay(const SphereProjection& s, const PixelCoord& p);

/// @brief Brute-force oracle: the LINE through the eye and pixel @p p meets the sphere,
/// |c × v|/|v| ≤ r (DESIGN §2).
bool rayHitsSphere(const SphereProjection& s, const PixelCoord& p);

/// @brief Exact normalised ray–centre distance d = |c × v| / (|v|·r) (DESIGN §3); d ≤ 1 on hits.
double exactRayDistance(const SphereProjection& s, const PixelCoord& p);

/// @brief d² = |c × v|² / (|v|²·r²) without square roots: the fast exact per-pixel path
/// (≈ 20 flops and one division, comparable to the affine index + reindex lookup).
double exactRayDistance2(const SphereProjection& s, const PixelCoord& p);

/// @brief The exact line integral, in voxel units, of the normalised kernel along the
/// HALF-ray t ≥ 0 from the eye through pixel @p p (Kernel::segmentIntegral). Equals
/// Kernel::footprint(R·exactRayDistance) for an Ellipse; the fallback for EyeInside and
/// Straddles (the part of the kernel behind the eye is not seen). Deposit = σ·h·this.
/// @p kernel: the kernel whose support the sphere is (s.r = kernel.radius()·h).
double halfRayFootprint(const SphereProjection& s, const PixelCoord& p,
                        const KernelShape& kernel = KernelShape::standard());

}  // namespace vdbsplat
