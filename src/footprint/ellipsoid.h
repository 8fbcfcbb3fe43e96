// footprint/ellipsoid.h — the exact perspective projection of one kernel ELLIPSOID: DESIGN §2
// generalised through the kernel's index space (docs/kernel.md, "Any voxel shape").
// Owns: VoxelShape (the linear part M of a grid's index→view map, its inverse, singular
// values and volume), projectEllipsoid (class, the silhouette ellipse, and a SphereProjection
// stand-in carrying it so that the EWA widening of screen_kernel.h applies unchanged), the
// exact index-space ray–centre distance and its ExactIndexMap, the half-ray integral for
// kernels at the eye, and an independent brute-force oracle (ray–quadric intersection).
//
// A grid with any affine index→world map A (anisotropic voxels, rotation, shear) has kernels
// g(A⁻¹(x − x_k)): ellipsoids E = {c + M·u : |u| ≤ R} in view space, M = R_view·A. A pixel's
// ray v (eye at the origin) becomes, in the kernel's index space, the line through o' = −M⁻¹c
// with direction v' = M⁻¹v, and the distance from the kernel centre to it is
//     d·R = |o' × v'| / |v'| = |Mᵀ(c × v)| / (|det M|·|M⁻¹v|)        (cof(M⁻¹) = Mᵀ/det M)
// a ratio of two quadratic forms in v, so the silhouette d = 1 is a conic on the image plane:
//     vᵀ(R²·M⁻ᵀM⁻¹ − [c]ₓᵀ M Mᵀ [c]ₓ / det²M) v = 0,
// an ellipse when the ellipsoid lies in front of the eye plane (the quadric's silhouette cone
// cut by the image plane). For M = h·(rotation) it is DESIGN §2's ellipse.
#pragma once
#include <glm/glm.hpp>

#include "camera/camera.h"
#include "footprint/ellipse.h"
#include "footprint/screen_kernel.h"

namespace vdbsplat {

/// @brief The shape of every kernel of a grid in view space (one per render).
struct VoxelShape {
    glm::dmat3 M{1.0};   ///< index → view linear part (world units per index unit)
    glm::dmat3 N{1.0};   ///< M⁻¹
    double volume = 1.0; ///< |det M|: the kernel's world volume per unit index volume (h³ for cubes)
    double h = 1.0;      ///< |det M|^(1/3): the voxel size the energy rule and the transfer function use
    double sMax = 1.0, sMin = 1.0;  ///< largest and smallest singular values of M (semi-axes per index unit)
    bool sphere = true;  ///< M = h·(rotation) to 1e−9: the sphere paths (tables, DESIGN §2) apply

    /// @brief The shape of the linear map @p m (must be non-singular).
    static VoxelShape of(const glm::dmat3& m);
    /// @brief World length per unit of index length along view direction @p v (any length):
    /// |v| / |M⁻¹v|; h for a sphere.
    double lengthAlong(const glm::dvec3& v) const { return glm::length(v) / glm::length(N * v); }
    /// @brief The isotropic spacing whose square is the mean screen-axis variance of the kernel's
    /// on-axis projection per s_g²: √((‖M‖²_F − |row_z(M)|²)/2) (view space); h for a sphere.
    /// A point's filter takes it (pointfilter/point_filter.h), as the level of detail's spread
    /// takes the trace/2 of its projected covariance.
    double projectedSpacing() const {
        double sum = 0.0;
        for (int c = 0; c < 3; ++c) sum += M[c].x * M[c].x + M[c].y * M[c].y;
        return std::sqrt(0.5 * sum);
    }
};

/// @brief Singular values of @p m, largest first (eigenvalues of mᵀm, closed form for
/// symmetric 3×3: Smith 1961).
glm::dvec3 singularValues(const glm::dmat3& m);

/// @brief How one kernel ellipsoid projects. `ellipse` is a SphereProjection whose
/// ellipse fields (centre, u, a, b, bounds, toUnit) are the ellipsoid's exact silhouette and
/// whose c, f, principal are the kernel's: makeScreenKernel widens it as any other. For the
/// other classes `ellipse.bounds` is a conservative box (the bounding sphere's, radius R·sMax).
struct EllipsoidProjection {
    SphereClass kind = SphereClass::Behind;
    SphereProjection ellipse;
    double lengthScale = 0.0;  ///< world length per index length along the centre ray, |c|/|M⁻¹c|
};

/// @brief Projects the kernel of @p shape (radius Kernel::kRadius in index units) centred at
/// view point @p c through a pinhole (focal @p f px, principal point @p principal).
/// Behind: entirely behind the eye plane. EyeInside: |M⁻¹c| ≤ R. Straddles: the ellipsoid
/// crosses the eye plane (its z-extent R·|row₃(M)| ≥ c.z) or the conic is degenerate.
/// Ellipse otherwise. Never NaN; non-finite input gives Behind.
EllipsoidProjection projectEllipsoid(const VoxelShape& shape, const ViewPoint& c, double f, const PixelCoord& principal);

/// @brief The normalised index-space distance² d² from the kernel centre @p c to the line
/// through the eye along view direction @p v (the formula above), without square roots.
double ellipsoidRayDistance2(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v);

/// @brief Brute-force oracle, independent of the index-space formula: the line t·v meets the
/// world-space quadric (x − c)ᵀ M⁻ᵀM⁻¹ (x − c) ≤ R² (its discriminant is ≥ 0).
bool rayHitsEllipsoid(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v);

/// @brief The ExactIndexMap of the widened kernel @p k of an ellipsoid projection @p e
/// (δ from @p origin): the pulled-back pixel's ray carried into index space, v' = M⁻¹v, where
/// the kernel is a ball, so that d² = 1 − (1 − i²)·κ/|v'|² as for spheres — the same map the
/// compositor's exact-index loop reads for spheres.
ExactIndexMap makeEllipsoidIndexMap(const ScreenKernel& k, const EllipsoidProjection& e, const VoxelShape& shape,
                                    const PixelCoord& origin);

/// @brief The optical depth per unit σ·(voxel length) deposited on the HALF-ray from the
/// eye along view direction @p v by the kernel at @p c (the fallback for kernels at the eye,
/// as halfRayFootprint for spheres): the index-space half-ray integral of the normalised
/// kernel times the world length per index length along v, over h (σ_k·h·this = τ).
double ellipsoidHalfRayDeposit(const VoxelShape& shape, const ViewPoint& c, const glm::dvec3& v);

}  // namespace vdbsplat
