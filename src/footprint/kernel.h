// footprint/kernel.h — the reconstruction kernel every mode shares (DESIGN §1).
// Owns: the truncated Gaussian g, its normalisation to unit volume integral over
// its truncated support, and its closed-form line integrals (the footprint F).
//
// Choice (documented in docs/kernel.md): s_g = 0.65 voxel, R = 2.0 voxels
// (≈ 3.08 s_g). The partition-of-unity ripple of the untruncated Gaussian is
// 2·exp(−2π²s_g²) ≈ 4.8e−4 (DESIGN §1); the truncation's edge step dominates it: the
// truncated kernels of a uniform lattice sum to a field within [0.9884, 1.0102], and
// their footprints along an axis-aligned ray to [0.9944, 1.0023] (docs/kernel.md §2,
// pinned by Kernel.TruncatedPartitionOfUnityRippleIsAsDocumented). The reference integrates the same
// field, so the ripple is never counted as an error of a forward mode.
//
// Units: "voxel units" — distances divided by the voxel size h.
#pragma once
#include <string>

namespace vdbsplat {

/// @brief One truncated Gaussian reconstruction kernel (DESIGN §1), normalised to unit volume
/// integral over its support (voxel units): the study axis `--kernel` (docs/kernel.md §10).
/// `Kernel` below is the standard one; KernelShape::sharp() is a narrower Gaussian whose
/// response at the grid's Nyquist frequency is closer to trilinear's. Every radius here is
/// ≤ Kernel::kRadius, which the stream's culling and the crop use as the bound.
class KernelShape {
public:
    /// @param id the --kernel name; @param tableName the name written into table headers.
    KernelShape(const char* id, const char* tableName, double sigma, double radius);

    const char* id() const { return id_; }
    const char* tableName() const { return tableName_; }
    double sigma() const { return sigma_; }    ///< s_g (voxels)
    double radius() const { return radius_; }  ///< R (voxels)
    double normalization() const { return norm_; }  ///< 1 / ∫_{|x|<R} exp(−|x|²/2s_g²) dV

    /// @brief g(x) for |x|² = @p s2 (voxel units²); 0 outside the support.
    double value(double s2) const;
    /// @brief The line integral of g along a ray at distance @p rho from the centre between
    /// signed parameters @p t0 ≤ @p t1 from the closest point (voxel units), clipped to the chord.
    double segmentIntegral(double rho, double t0, double t1) const;
    /// @brief F(ρ), the line integral along the full chord (closed form with erf); ∫∫F dA = 1.
    double footprint(double rho) const { return segmentIntegral(rho, -radius_, radius_); }
    /// @brief ∫∫ F over the plane, numerically (midpoint rule; for tests).
    double footprintPlaneIntegral(int steps = 4096) const;
    /// @brief The 3D integral of g over its support, numerically on a @p n³ grid (for tests: 1).
    double volumeIntegral(int n = 160) const;

    /// The standard kernel (Kernel's constants): --kernel gaussian.
    static const KernelShape& standard();
    /// s_g = 0.5, R = 1.55 (3.1 s_g): --kernel gaussian-sharp.
    static const KernelShape& sharp();
    /// @throw Error "--kernel: unknown kernel '<name>' (choose gaussian, gaussian-sharp)".
    static const KernelShape& named(const std::string& name);
    static constexpr const char* kNames = "gaussian, gaussian-sharp";  ///< for --help and errors

private:
    const char* id_;
    const char* tableName_;
    double sigma_, radius_, norm_;
};

/// The standard kernel as constants (KernelShape::standard() is the same kernel as a value).
struct Kernel {
    static constexpr double kSigma = 0.65;   ///< s_g, the Gaussian's standard deviation (voxels)
    static constexpr double kRadius = 2.0;   ///< R, the truncation radius (voxels)
    static constexpr const char* kName = "gaussian-s0.65-R2.0";  ///< written into table headers

    /// @brief 1 / ∫_{|x|<R} exp(−|x|²/(2 s_g²)) dV, so that ∫ g dV = 1 (voxel units).
    static double normalization();

    /// @brief g(x) for |x|² = @p s2 (voxel units²); 0 outside the support.
    static double value(double s2);

    /// @brief F(ρ): the line integral of g along a full chord at distance ρ (voxel units)
    /// from the centre; 0 for ρ ≥ R. Closed form with erf (DESIGN §3). ∫∫ F dA = 1.
    static double footprint(double rho);

    /// @brief The line integral of g along a ray at distance ρ from the centre,
    /// between signed ray parameters @p t0 ≤ @p t1 measured from the closest point
    /// (voxel units), clipped to the chord.
    static double segmentIntegral(double rho, double t0, double t1);

    /// @brief ∫∫ F over the plane, numerically; 1 up to quadrature error (used by tests).
    static double footprintPlaneIntegral(int steps = 4096);
};

}  // namespace vdbsplat
