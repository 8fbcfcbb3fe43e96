// render/project.h — the projection stage: classified voxels → projected primitives.
// Owns: the point/splat decision (projected voxel spacing h·f/z against the
// threshold τ, DESIGN §4), and building each primitive's screen kernel: the
// filtered point (pointfilter/), the EWA splat (footprint/screen_kernel.h), or
// the near-eye fallback (footprint/ellipse.h). Runs in parallel; primitive i
// always comes from voxel i, so the order stays deterministic.
#pragma once
#include <optional>
#include <span>
#include <vector>

#include "camera/camera.h"
#include "composite/compositor.h"
#include "composite/primitive.h"
#include "footprint/ellipsoid.h"
#include "footprint/prefilter.h"
#include "footprint/tables.h"
#include "render/project_vector.h"
#include "render/settings.h"
#include "volume/stream.h"

namespace vdbsplat {

/// --footprint auto: splats whose affine index may be off by more than this (in d, the
/// normalised ray–centre distance; SphereProjection::affineIndexError) take the exact index.
/// 5e−4 in d is ≈ 1e−3 of the footprint's peak, 12× the footprint table's own error.
inline constexpr double kAutoExactIndexError = 5e-4;

struct ProjectionContext {
    const Camera& camera;
    const Tables& tables;
    double voxelSize;     ///< h (world units)
    double slabLength;    ///< world length of one slab
    RenderMode mode;      ///< Hybrid, Splat or Point
    double threshold;     ///< τ in pixels
    FootprintPath footprint;
    bool showPrimitives;
    /// The screen low-pass V_h folded into every minified primitive (px²): kPrefilterVariance, or
    /// the sub-pixel grid's small one when the prefilter is applied after compositing (postfilter.h).
    double prefilterVariance = kPrefilterVariance;
    /// The low-pass folded into magnified primitives (px²), where the ramp from prefilterVariance
    /// ends (lowPass()): the same, or the sub-pixel grid's smaller one.
    double magnifiedPrefilterVariance = kPrefilterVariance;
    /// The kernels' shape in view space (footprint/ellipsoid.h); null or a sphere: the sphere
    /// paths. An ellipsoid (anisotropic or sheared voxels) decides point/splat by its longest
    /// axis, filters points with its projected spacing, and is splatted through its exact
    /// silhouette and the exact index-space distance (SplatExactIndex; --footprint does not apply).
    const VoxelShape* shape = nullptr;
    /// The compositor whose opaque tiles hide primitives (null: none): a primitive whose pixels
    /// all lie in opaque tiles is counted as hidden and not passed on (ProjectionCounts), as the
    /// compositor's binning would skip it, so it is neither sorted nor binned.
    const TileCompositor* occlusion = nullptr;
    /// Points' filter set up through the vector sum (setupPointVector); false: setupPoint, the
    /// scalar oracle (--simd off). The same values either way.
    bool vector = true;
    /// --compositing slabs: each drawn primitive gets the fractions of its optical depth for the
    /// slabs around its own (composite/slab_profile.h; `reach` as the compositor's), from the
    /// kernel's tabulated marginal `marginal` (required when slabs.on).
    SlabCompositing slabs = {};
    const MarginalCdfTable* marginal = nullptr;

    /// The low-pass of a primitive by its projected spacing: prefilterVariance up to half a
    /// pixel, magnifiedPrefilterVariance from one (footprint/prefilter.h).
    PrefilterRamp lowPass() const { return PrefilterRamp(prefilterVariance, magnifiedPrefilterVariance); }
};

/// What one window's primitives draw, before the compositor's occlusion culling (integer sums:
/// the same for any split of the work).
struct ProjectionCounts {
    uint64_t points = 0, splats = 0, exactIndexSplats = 0, lodAggregates = 0, lodVoxels = 0, drawnVoxels = 0;
    SkippedPrimitives hidden;  ///< of those, hidden behind opaque tiles (ProjectionContext::occlusion)
    ProjectionCounts& operator+=(const ProjectionCounts& o) {
        points += o.points, splats += o.splats, exactIndexSplats += o.exactIndexSplats;
        lodAggregates += o.lodAggregates, lodVoxels += o.lodVoxels, drawnVoxels += o.drawnVoxels;
        hidden.points += o.hidden.points, hidden.splats += o.hidden.splats;
        hidden.exactIndexSplats += o.hidden.exactIndexSplats, hidden.voxels += o.hidden.voxels;
        return *this;
    }
};

/// @brief What projectSplatsVector (render/project_vector.h) needs of @p ctx, where it applies:
/// sphere kernels in hybrid or splat-only mode, --simd on (ctx.vector), the footprint not `exact`
/// (whose splats are recomputed per tile), and a camera projectSphere accepts. nullopt: every
/// voxel takes projectVoxel. projectBatch projects through it, lanes it declines through projectVoxel.
std::optional<SplatLaneContext> splatLaneContext(const ProjectionContext& ctx);

/// @brief What projectPointsVector needs of @p ctx, where it applies: sphere kernels in hybrid or
/// point mode, --simd on. projectBatch uses it beside splatLaneContext: the lanes the splats leave
/// that are points take it, the rest projectVoxel.
std::optional<PointLaneContext> pointLaneContext(const ProjectionContext& ctx);

/// @brief Projects every voxel of @p batch into @p window (grown when needed, never shrunk: it
/// is reused window after window): each voxel through projectVoxel, with the voxel's depth, its
/// slab clamped to the batch's, and its member count; window.slabBase is the batch's first slab.
/// The window is compacted by blocks (ProjectedWindow::kBlock): the drawn primitives of voxels
/// [b·kBlock, (b + 1)·kBlock) fill those slots from the front in voxel order, the rest are not
/// drawn. @return what the primitives draw, by kind.
ProjectionCounts projectBatch(const VoxelBatch& batch, const ProjectionContext& ctx, ProjectedWindow& window);

/// @brief projectBatch for a window read where the stream left its voxels (StreamWindow: runs of
/// its chunks and pending records): primitive k from the window's voxel k, split among threads
/// by primitives. The same primitives as projectBatch of the window copied out.
ProjectionCounts projectWindow(const StreamWindow& voxels, const ProjectionContext& ctx, ProjectedWindow& window);

/// @brief --compositing slabs: the slab fractions of a primitive at view position @p c, distance
/// @p distance, in slab @p slab, whose kernel is @p ctx's (a sphere of h, or ctx.shape's ellipsoid)
/// widened along the view ray by an aggregate's second moment @p depthSpread (world²): its
/// profile along the ray is the kernel's marginal with the kernel unit a world units, a² =
/// |Mᵀω|² + depthSpread / s_g² (ω = c/|c|; |Mᵀω| = h for a sphere), matching the variance.
SlabProfile slabProfileFor(const glm::dvec3& c, double distance, int64_t slab, float depthSpread, const ProjectionContext& ctx);

/// @brief Projects one voxel (view-space centre @p c, extinction per voxel length @p sigma).
/// @param spreadPx2 a level-of-detail aggregate's projected second moment (px², added to
/// the point filter's variance; 0 for a single voxel).
Primitive projectVoxel(const glm::dvec3& c, float sigma, const glm::vec3& color, const ProjectionContext& ctx,
                       float spreadPx2 = 0.f);

}  // namespace vdbsplat
