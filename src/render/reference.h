// render/reference.h — the ground truth: a supersampled ray integrator of the
// continuous field of DESIGN §1.
// Owns: RayIntegrator (one ray through σ(x) = Σ σ_k g((x − x_k)/h), the
// emission–absorption integral with exact per-bin optical depth) and
// renderReference (several jittered rays per pixel, band-limited by the
// Gaussian prefilter h_p of footprint/prefilter.h before sampling pixel centres).
//
// Method, per ray (in the grid's index space, where the kernel has radius R):
//  1. gather every active kernel whose sphere the ray crosses, slice by slice
//     along the ray's major axis (each voxel is visited once), visiting only the
//     slices that pass near an active region (ActiveRegions: boxes from the tree's
//     leaves and active tiles), so empty space costs nothing — the time follows the
//     active voxels along the rays, not the bounding box;
//  2. deposit each kernel's exact line integral (erf, Kernel::segmentIntegral)
//     into depth bins of kBinLength voxels — optical depth and emission;
//  3. composite finished bins front to back (α = 1 − exp(−τ)) as the slice
//     front passes them, and stop once transmittance < kReferenceEpsilon.
// The only approximation is the order of emission inside one bin.
#pragma once
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "camera/camera.h"
#include "footprint/kernel.h"
#include "image/image.h"
#include "render/settings.h"
#include "shading/shading_field.h"
#include "volume/emission.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// Depth bin length along the ray, in voxels.
inline constexpr double kBinLength = 0.25;
/// A ray stops once its transmittance falls below this.
inline constexpr double kReferenceEpsilon = 1e-4;

/// @brief Index-space boxes that together hold every active voxel of a grid: one per
/// lowest internal node (128³ voxels) with the union of its leaves and small tiles,
/// and one per larger active tile. Built once per render (cost follows the leaf count).
class ActiveRegions {
public:
    explicit ActiveRegions(const openvdb::FloatTree& tree);
    const std::vector<openvdb::CoordBBox>& boxes() const { return boxes_; }

private:
    std::vector<openvdb::CoordBBox> boxes_;
};

/// @brief Integrates single rays through a volume; one per thread (it owns scratch memory
/// and a tree accessor, never shared across threads).
class RayIntegrator {
public:
    /// @p regions: the volume's ActiveRegions, shared by every integrator of a render; when
    /// null the integrator builds its own.
    /// @p shading: per-voxel shading factors applied after classification (nullptr: none).
    /// @p emission: each voxel's emission, added after shading (nullptr: none; docs/emission.md).
    /// @p kernel: the reconstruction kernel integrated (--kernel; the standard one by default).
    RayIntegrator(const Volume& volume, const ClassificationTable& table, const ActiveRegions* regions = nullptr,
                  const ShadingField* shading = nullptr, const EmissionSource* emission = nullptr,
                  const KernelShape& kernel = KernelShape::standard());
    /// @brief Premultiplied RGB and alpha = 1 − T of the ray from world point @p origin
    /// along world direction @p direction (any length), from the origin to infinity.
    glm::dvec4 integrate(const glm::dvec3& origin, const glm::dvec3& direction);
    /// @brief Optical depth ∫σ along the whole ray (no early termination), for tests.
    double opticalDepth(const glm::dvec3& origin, const glm::dvec3& direction);

    /// One depth bin of a ray: optical depth and emitted radiance deposited in it.
    struct Bin { double tau = 0.0; glm::dvec3 emission{0.0}; };

private:
    template <typename Visit> void gather(const glm::dvec3& oIdx, const glm::dvec3& dIdx, double tEnter, double tExit,
                                          Visit&& visit);
    /// The voxel's classification, shaded when the integrator has a shading field.
    Classified classify(const openvdb::Coord& ijk, float value);
    bool clip(const glm::dvec3& oIdx, const glm::dvec3& dIdx, double& tEnter, double& tExit) const;
    /// A run of slice indices [first, last] along the major axis.
    struct SliceRange { int64_t first, last; };
    /// The slices in [kLo, kHi] along axis m that can hold a kernel the ray reaches (a slice's
    /// kernel disc has lateral half-extents ea, eb): ascending, disjoint, merged.
    std::vector<SliceRange>& sliceRanges(const glm::dvec3& o, const glm::dvec3& d, int m, double ea, double eb,
                                         int64_t kLo, int64_t kHi);

    const Volume& volume_;
    const ClassificationTable& table_;
    const KernelShape& kernel_;
    double kernelR2_;  ///< R² of kernel_ (voxel units²)
    openvdb::FloatGrid::ConstAccessor accessor_;
    std::unique_ptr<ShadingField::Accessor> shading_;  ///< null when unshaded
    const EmissionSource* emission_;
    std::unique_ptr<EmissionSource::Accessor> emissionAccessor_;  ///< null without emission
    std::vector<Bin> bins_;
    std::unique_ptr<ActiveRegions> ownRegions_;
    const ActiveRegions* regions_;
    std::vector<SliceRange> ranges_;  ///< scratch for sliceRanges
};

/// @brief Renders the reference image: ⌈√spp⌉² stratified, jittered rays per pixel (a
/// deterministic hash of pixel and sample picks the jitter, so the image does not depend on
/// the thread count), each pixel the prefilter-weighted mean of the samples within
/// kPrefilterCutoffSigmas standard deviations of its centre.
/// @param control progress (fraction of sample rows traced) and stop (polled per sample row).
/// @throw RenderStopped when control.stop returned true.
/// @param emission each voxel's emission (nullptr: none), as RayIntegrator.
Image renderReference(const Volume& volume, const ClassificationTable& table, const Camera& camera, int spp,
                      RenderStats& stats, const ShadingField* shading = nullptr,
                      const RenderControl& control = {}, const EmissionSource* emission = nullptr,
                      const KernelShape& kernel = KernelShape::standard());

}  // namespace vdbsplat
