// render/project.cpp — point/splat classification and screen kernels (see project.h).
#include "render/project.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "footprint/ellipse.h"
#include "footprint/ellipsoid.h"
#include "footprint/kernel.h"
#include "footprint/screen_kernel.h"
#include "pointfilter/point_filter.h"
#include "render/project_modes.h"
#include "render/project_vector.h"

namespace vdbsplat {

namespace {

/// --show-primitives: splats tinted red (Yuan et al. 2003, Figure 8a), points unchanged.
glm::vec3 splatTint(const glm::vec3& c) {
    const float luma = std::max(0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z, 0.25f);
    return glm::vec3(1.0f, 0.12f, 0.12f) * luma;
}

/// A point of filter spacing @p spacingPx carrying the low-pass @p lowPass (px²; ctx.lowPass()).
Primitive makePoint(const glm::dvec3& c, float sigma, double spacingPx, double lowPass, float spreadPx2, const ProjectionContext& ctx) {
    Primitive p;
    const PixelCoord centre = ctx.camera.project(c);
    if (!std::isfinite(centre.x) || !std::isfinite(centre.y)) return p;
    p.kind = PrimitiveKind::Point;
    p.centre = glm::vec2(centre);
    p.variance = float(pointFilterVariance(spacingPx, lowPass, ctx.tables.kernel->sigma()) + spreadPx2);  // + an aggregate's spread (DESIGN §8.2)
    // σ·M·(f/z)²·(D/z) with σ per world unit = sigma / h (DESIGN §4).
    p.total = float(pointDepositTotal(sigma / ctx.voxelSize, ctx.voxelSize, ctx.camera.focal(), c));
    PixelBox box;
    box.lo = centre - kPointMaxRadiusPx;
    box.hi = centre + kPointMaxRadiusPx;
    p.range = pixelRange(box, ctx.camera.width(), ctx.camera.height());
    if (p.range.empty() || !(p.total > 0.f)) p.kind = PrimitiveKind::Culled;
    return p;
}

/// The point's filter, once (PointSetup): the compositor then evaluates only the pixels of
/// each tile it touches, and bins it by its footprint instead of the ±kPointMaxRadiusPx box.
void setUpPointFilter(Primitive& p, int width, int height, bool vector) {
    const PixelCoord centre(p.centre);
    const PointSetup s = vector ? setupPointVector(centre, double(p.variance)) : setupPoint(centre, double(p.variance));
    p.pointInvVariance = s.invVariance, p.pointRadius2 = s.radius2, p.pointNorm = s.norm;
    if (s.empty()) {
        p.range = {};
        return;
    }
    // The footprint lies inside the ±kPointMaxRadiusPx box it replaces (r_s ≤ kPointMaxRadiusPx).
    p.range.x0 = std::max(s.x0, 0), p.range.y0 = std::max(s.y0, 0);
    p.range.x1 = std::min(s.x0 + s.nx - 1, width - 1), p.range.y1 = std::min(s.y0 + s.ny - 1, height - 1);
}

/// A splat of projected spacing @p spacingPx carrying the low-pass @p lowPass (px²; ctx.lowPass()).
Primitive makeSplat(const glm::dvec3& c, float sigma, double spacingPx, double lowPass, const ProjectionContext& ctx) {
    Primitive p;
    const double h = ctx.voxelSize;
    const SphereProjection sphere = projectSphere(ctx.camera, c, ctx.tables.kernel->radius() * h);
    p.viewPos = glm::vec3(c);
    p.sigma = sigma;
    switch (sphere.kind) {
        case SphereClass::Behind: return p;
        case SphereClass::EyeInside:
        case SphereClass::Straddles:
            p.kind = PrimitiveKind::NearEye;
            p.range = pixelRange(sphere.bounds, ctx.camera.width(), ctx.camera.height());
            break;
        case SphereClass::Ellipse: {
            if (ctx.mode == RenderMode::Ewa) {  // Zwicker et al. 2001: the affine kernel (project_modes.h)
                fillEwaSplat(p, c, sigma, ctx);
                break;
            }
            const ScreenKernel kernel = splatKernelFor(sphere, spacingPx, lowPass, ctx);  // Swan's stretch or V + V_h
            p.kind = keepsTablePath(spacingPx, ctx)            ? PrimitiveKind::Splat
                     : ctx.footprint == FootprintPath::Exact ? PrimitiveKind::SplatExact
                     : ctx.footprint == FootprintPath::Auto && sphere.affineIndexError() > kAutoExactIndexError
                         ? PrimitiveKind::SplatExactIndex
                         : PrimitiveKind::Splat;
            p.centre = glm::vec2(kernel.centre);
            p.conic = glm::vec3(kernel.conic[0][0], kernel.conic[0][1], kernel.conic[1][1]);
            p.scale = float(sigma * kernel.amplitude);  // σ·h·amplitude with σ per world unit = sigma/h
            p.sin2Alpha = float(sphere.sinAlpha * sphere.sinAlpha);  // sin α = r/D
            if (p.kind == PrimitiveKind::SplatExactIndex) {
                // δ from the kernel's own (double) centre: the float centre the loop measures from
                // differs by < 2⁻²⁴ of it (g++ 12 folded the round trip through float away here, so
                // this was already the map; stated, so that every compiler makes the same one).
                p.exactMap = makeExactIndexMap(kernel, sphere, kernel.centre);
                p.hasExactMap = true;
            }
            p.range = pixelRange(kernel.bounds, ctx.camera.width(), ctx.camera.height());
            break;
        }
    }
    if (p.range.empty()) p.kind = PrimitiveKind::Culled;
    return p;
}

/// An ellipsoid kernel (footprint/ellipsoid.h): its exact silhouette widened by the low-pass,
/// and the exact index-space ray–centre distance per pixel (an ExactIndexMap in index space),
/// read by the compositor's exact-index path. τ = σ_world·L·F(d), L the world length per index
/// length, taken along the centre ray (it varies by ~(anisotropy)·α over the footprint;
/// docs/kernel.md, "Any voxel shape"); kernels at the eye take the exact half-ray integral.
Primitive makeEllipsoidSplat(const glm::dvec3& c, float sigma, double lowPass, const ProjectionContext& ctx) {
    Primitive p;
    const VoxelShape& shape = *ctx.shape;
    const EllipsoidProjection e = projectEllipsoid(shape, c, ctx.camera.focal(), ctx.camera.principal());
    p.viewPos = glm::vec3(c);
    p.sigma = sigma;
    switch (e.kind) {
        case SphereClass::Behind: return p;
        case SphereClass::EyeInside:
        case SphereClass::Straddles:
            p.kind = PrimitiveKind::NearEye;
            p.range = pixelRange(e.ellipse.bounds, ctx.camera.width(), ctx.camera.height());
            break;
        case SphereClass::Ellipse: {
            const ScreenKernel kernel = makeScreenKernel(e.ellipse, lowPass);
            p.kind = PrimitiveKind::SplatExactIndex;
            p.centre = glm::vec2(kernel.centre);
            p.conic = glm::vec3(kernel.conic[0][0], kernel.conic[0][1], kernel.conic[1][1]);
            p.scale = float(sigma / ctx.voxelSize * e.lengthScale * kernel.amplitude);  // σ_world·L·amplitude
            p.sin2Alpha = float(e.ellipse.sinAlpha * e.ellipse.sinAlpha);
            p.exactMap = makeEllipsoidIndexMap(kernel, e, shape, PixelCoord(p.centre));
            p.hasExactMap = true;
            p.range = pixelRange(kernel.bounds, ctx.camera.width(), ctx.camera.height());
            break;
        }
    }
    if (p.range.empty()) p.kind = PrimitiveKind::Culled;
    return p;
}

/// Up to kSplatLanes consecutive voxels of a window gathered from the ends of its runs
/// (StreamWindow: a run shorter than a lane group, or what a group leaves of one) into one
/// thread's scratch.
struct LaneVoxels {
    std::array<glm::vec3, kSplatLanes> viewPos, color;
    std::array<float, kSplatLanes> distance, sigma, spread, depthSpread;
    std::array<uint32_t, kSplatLanes> members;
    bool withDepthSpread = false;
    size_t n = 0;
    /// Records [@p i, @p i + @p m) of @p batch appended (m ≤ kSplatLanes − n). Record by record:
    /// m is short, and a library copy per array cost more than the records (docs/performance.md,
    /// session 43).
    void append(const VoxelBatch& batch, size_t i, size_t m) {
        const glm::vec3* p = batch.viewPos.data() + i;
        const glm::vec3* c = batch.color.data() + i;
        const float *d = batch.distance.data() + i, *s = batch.sigma.data() + i, *sp = batch.spread.data() + i;
        const uint32_t* mb = batch.members.data() + i;
        for (size_t q = 0; q < m; ++q) {
            viewPos[n + q] = p[q], color[n + q] = c[q];
            distance[n + q] = d[q], sigma[n + q] = s[q], spread[n + q] = sp[q], members[n + q] = mb[q];
        }
        if (withDepthSpread)
            for (size_t q = 0; q < m; ++q) depthSpread[n + q] = batch.depthSpread[i + q];
        n += m;
    }
};

/// kSplatLanes or fewer consecutive voxels of a window as the projection reads them: a run of a
/// buffer's records where they lie (LaneView::in), or a LaneVoxels scratch that gathered the
/// ends of several runs (LaneView::of).
struct LaneView {
    const glm::vec3 *viewPos, *color;
    const float *distance, *sigma, *spread, *depthSpread;  ///< depthSpread: null without
    const uint32_t* members;
    size_t n;
    static LaneView in(const VoxelBatch& b, size_t i, size_t n) {
        return {b.viewPos.data() + i, b.color.data() + i, b.distance.data() + i, b.sigma.data() + i, b.spread.data() + i,
                b.depthSpread.empty() ? nullptr : b.depthSpread.data() + i, b.members.data() + i, n};
    }
    static LaneView of(const LaneVoxels& g) {
        return {g.viewPos.data(), g.color.data(), g.distance.data(), g.sigma.data(), g.spread.data(),
                g.withDepthSpread ? g.depthSpread.data() : nullptr, g.members.data(), g.n};
    }
};

/// makeSplat's splat from lane @p k of a projectSplatsVector call, stored straight into
/// @p window as primitive @p i (the fields set() would write from that Primitive; no Primitive
/// is built), an exact-index splat's map in exactMaps[@p map] (i's block's next free map slot).
/// Returns its kind (Culled when it has no pixel on the image) and sets @p range.
PrimitiveKind storeLaneSplat(const SplatLanes& lanes, size_t k, size_t i, size_t map, const LaneView& batch, int64_t slab,
                             const ProjectionContext& ctx, ProjectedWindow& window, PixelRange& range) {
    const uint8_t status = lanes.status[k];
    PrimitiveRecord& q = window.records[i];
    const PrimitiveKind kind = status & SplatLanes::kOffImage     ? PrimitiveKind::Culled
                               : status & SplatLanes::kExactIndex ? PrimitiveKind::SplatExactIndex
                                                                  : PrimitiveKind::Splat;
    q.kind = kind;
    q.hasExactMap = (status & SplatLanes::kExactIndex) != 0;  // as makeSplat: kept when culled
    q.centre = glm::vec2(float(lanes.centreX[k]), float(lanes.centreY[k]));
    q.shape = glm::vec3(float(lanes.conicXX[k]), float(lanes.conicXY[k]), float(lanes.conicYY[k]));
    q.scale = float(batch.sigma[k] * lanes.amplitude[k]);
    q.sin2Alpha = float(lanes.sinAlpha[k] * lanes.sinAlpha[k]);
    q.color = ctx.showPrimitives ? splatTint(batch.color[k]) : batch.color[k];
    q.range = range = lanes.range(k);
    window.place(i, slab, batch.distance[k], batch.members[k], kind, range);
    if (kind == PrimitiveKind::SplatExactIndex) lanes.exactMapInto(k, window.mapSlotFor(i, map));  // it has its map: in place
    return kind;
}

/// makePoint's point, set up as setUpPointFilter does, from lane @p k of a projectPointsVector
/// call, stored straight into @p window as primitive @p i (as storeLaneSplat); sets @p range.
void storeLanePoint(const PointLanes& lanes, size_t k, size_t i, const LaneView& batch, int64_t slab,
                    const ProjectionContext& ctx, ProjectedWindow& window, PixelRange& range) {
    PrimitiveRecord& q = window.records[i];
    q.kind = PrimitiveKind::Point;
    q.hasExactMap = false;
    q.centre = glm::vec2(lanes.centreX[k], lanes.centreY[k]);
    q.shape = glm::vec3(lanes.invVariance[k], lanes.total[k], lanes.norm[k]);
    q.scale = lanes.radius2[k];
    q.sin2Alpha = 0.f;
    q.color = batch.color[k];  // points are never tinted
    q.range = range = lanes.range(k, ctx.camera.width(), ctx.camera.height());
    window.place(i, slab, batch.distance[k], batch.members[k], PrimitiveKind::Point, range);
}

/// The voxels of @p group (n ≤ kSplatLanes) into the lanes, and projected there as splats and as
/// points where those contexts apply; the lanes past n hold zeros.
void projectChunkInLanes(const LaneView& group, const std::optional<SplatLaneContext>& splats,
                         const std::optional<PointLaneContext>& pointsIn, SplatLanes& lanes, PointLanes& points) {
    if (!splats && !pointsIn) return;
    const size_t n = group.n;
    for (size_t k = 0; k < n; ++k) {
        const glm::vec3& c = group.viewPos[k];
        lanes.x[k] = c.x, lanes.y[k] = c.y, lanes.z[k] = c.z;
    }
    for (size_t k = n; k < kSplatLanes; ++k) lanes.x[k] = lanes.y[k] = lanes.z[k] = 0.0;
    if (splats) projectSplatsVector(lanes, n, *splats);
    if (!pointsIn) return;
    std::copy_n(group.sigma, n, points.sigma);
    std::copy_n(group.spread, n, points.spread);
    std::fill(points.sigma + n, points.sigma + kSplatLanes, 0.f);
    std::fill(points.spread + n, points.spread + kSplatLanes, 0.f);
    projectPointsVector(lanes, points, n, *pointsIn);
}

}  // namespace

std::optional<PointLaneContext> pointLaneContext(const ProjectionContext& ctx) {
    const bool pointsOnly = ctx.mode == RenderMode::Point;
    if (!ctx.vector || (ctx.shape && !ctx.shape->sphere) || !(ctx.mode == RenderMode::Hybrid || pointsOnly)) return std::nullopt;
    PointLaneContext lanes;
    lanes.focal = ctx.camera.focal();
    lanes.principalX = ctx.camera.principal().x, lanes.principalY = ctx.camera.principal().y;
    lanes.spacingTimesFocal = ctx.voxelSize * ctx.camera.focal();
    lanes.threshold = pointsOnly ? INFINITY : ctx.threshold;  // point mode: every voxel in front of the eye
    lanes.voxelSize = ctx.voxelSize;
    lanes.lowPass = ctx.lowPass();
    lanes.kernelSigma = ctx.tables.kernel->sigma();
    lanes.width = ctx.camera.width(), lanes.height = ctx.camera.height();
    return lanes;
}

Primitive projectVoxel(const glm::dvec3& c, float sigma, const glm::vec3& color, const ProjectionContext& ctx,
                       float spreadPx2) {
    const bool ellipsoid = ctx.shape && !ctx.shape->sphere;
    // The projected voxel spacing h·f/z; for an ellipsoid its longest axis (a splat as soon as any
    // axis is magnified) decides, and its projected spacing sets the point filter.
    const double spacingPx = ctx.camera.spacingPx(ellipsoid ? ctx.shape->sMax : ctx.voxelSize, c.z);
    // Hybrid and None switch on the threshold; Splat, Ewa and Swan draw every voxel as a splat.
    const bool point = ctx.mode == RenderMode::Point ? c.z > 0.0
                       : drawsOnlySplats(ctx.mode) ? false
                                                   : spacingPx < ctx.threshold;
    const double filterPx = ellipsoid && c.z > 0.0 ? ctx.shape->projectedSpacing() * ctx.camera.focal() / c.z : spacingPx;
    // The low-pass by the spacing that decides point or splat: the same on both sides of the switch.
    const double lowPass = ctx.lowPass().at(spacingPx);
    Primitive p = point       ? makePoint(c, sigma, filterPx, lowPass, spreadPx2, ctx)
                  : ellipsoid ? makeEllipsoidSplat(c, sigma, lowPass, ctx)
                              : makeSplat(c, sigma, spacingPx, lowPass, ctx);
    if (point && ctx.mode == RenderMode::None && p.kind == PrimitiveKind::Point)
        snapToNearestPixel(p, ctx.camera.width(), ctx.camera.height());
    if (p.kind == PrimitiveKind::Point) setUpPointFilter(p, ctx.camera.width(), ctx.camera.height(), ctx.vector);
    p.color = (!point && ctx.showPrimitives) ? splatTint(color) : color;
    return p;
}

namespace {

/// What slabFractions takes of a primitive besides the kernel (slabProfileFor).
struct SlabProfileInput {
    double offset = 0.0;       ///< its centre, in slab lengths past the start of its own slab
    double unitInSlabs = 1.0;  ///< its kernel unit along the ray, in slab lengths
    int lowest = -kMaxSlabReach;  ///< the first slab it may reach, relative to its own (none before the eye)
};

SlabProfileInput slabProfileInput(const glm::dvec3& c, double distance, int64_t slab, float depthSpread, const ProjectionContext& ctx) {
    const KernelShape& kernel = *ctx.tables.kernel;
    const double length = glm::length(c);
    const glm::dvec3 omega = length > 0.0 ? c / length : glm::dvec3(0.0, 0.0, 1.0);
    // World length of one kernel unit along the ray: |Mᵀω| for the kernel x = M·u (its marginal
    // along ω is the sphere's, scaled by |Mᵀω|); h for a sphere.
    const double unit0 = ctx.shape && !ctx.shape->sphere ? glm::length(glm::transpose(ctx.shape->M) * omega) : ctx.voxelSize;
    const double s = kernel.sigma();
    const double unit = std::sqrt(unit0 * unit0 + double(depthSpread) / (s * s));
    return {distance / ctx.slabLength - double(slab), unit / ctx.slabLength, int(-std::min<int64_t>(slab, kMaxSlabReach))};
}

/// The slab profiles of up to kSplatLanes primitives of a projection chunk, computed together
/// (slabFractionsBatch: the same fractions as slabProfileFor's, a vector of primitives at a time)
/// and then stored into their window.
struct PendingProfiles {
    std::array<double, kSplatLanes> offset, unitInSlabs;
    std::array<int, kSplatLanes> lowest;
    std::array<size_t, kSplatLanes> index;
    std::array<SlabProfile, kSplatLanes> profile;
    size_t count = 0;

    void add(size_t i, const SlabProfileInput& in) {
        offset[count] = in.offset, unitInSlabs[count] = in.unitInSlabs, lowest[count] = in.lowest, index[count] = i;
        ++count;
    }
    /// Computes the pending profiles into their window; nothing when none is pending.
    void flush(const MarginalCdfTable* cdf, int reach, ProjectedWindow& window) {
        if (count == 0) return;
        slabFractionsBatch(*cdf, offset.data(), unitInSlabs.data(), lowest.data(), count, reach, profile.data());
        for (size_t k = 0; k < count; ++k) window.profile[index[k]] = profile[k];
        count = 0;
    }
};

}  // namespace

SlabProfile slabProfileFor(const glm::dvec3& c, double distance, int64_t slab, float depthSpread, const ProjectionContext& ctx) {
    const SlabProfileInput in = slabProfileInput(c, distance, slab, depthSpread, ctx);
    return ctx.marginal ? slabFractions(*ctx.marginal, in.offset, in.unitInSlabs, ctx.slabs.reach, in.lowest)
                        : slabFractions(*ctx.tables.kernel, in.offset, in.unitInSlabs, ctx.slabs.reach, in.lowest);
}

std::optional<SplatLaneContext> splatLaneContext(const ProjectionContext& ctx) {
    if (!ctx.vector || (ctx.shape && !ctx.shape->sphere) || ctx.footprint == FootprintPath::Exact) return std::nullopt;
    if (ctx.mode != RenderMode::Hybrid && ctx.mode != RenderMode::Splat) return std::nullopt;
    SplatLaneContext lanes;
    lanes.focal = ctx.camera.focal();
    lanes.principalX = ctx.camera.principal().x, lanes.principalY = ctx.camera.principal().y;
    lanes.radius = ctx.tables.kernel->radius() * ctx.voxelSize;  // makeSplat's sphere
    lanes.widenPerVariance = supportWideningPerVariance(*ctx.tables.kernel);
    lanes.lowPass = ctx.lowPass();
    lanes.spacingTimesFocal = ctx.voxelSize * ctx.camera.focal();
    lanes.threshold = ctx.threshold;
    lanes.pointsBelow = ctx.mode == RenderMode::Hybrid;
    lanes.autoExactIndex = ctx.footprint == FootprintPath::Auto;
    lanes.exactIndexError = kAutoExactIndexError;
    lanes.width = ctx.camera.width(), lanes.height = ctx.camera.height();
    const bool valid = lanes.radius > 0.0 && std::isfinite(lanes.radius) && lanes.focal > 0.0 && std::isfinite(lanes.focal) &&
                       std::isfinite(lanes.principalX) && std::isfinite(lanes.principalY);
    return valid ? std::optional(lanes) : std::nullopt;
}

ProjectionCounts projectBatch(const VoxelBatch& batch, const ProjectionContext& ctx, ProjectedWindow& window) {
    return projectWindow(StreamWindow::of(batch), ctx, window);
}

ProjectionCounts projectWindow(const StreamWindow& voxels, const ProjectionContext& ctx, ProjectedWindow& window) {
    window.slabBase = voxels.slabBegin;
    window.slabEnd = voxels.slabEnd;
    window.profiles = ctx.slabs.on;
    window.resize(voxels.size);
    const std::optional<SplatLaneContext> laneContext = splatLaneContext(ctx);
    // Points in lanes too (hybrid and point mode): the far views' and the clouds' voxels.
    const std::optional<PointLaneContext> pointContext = pointLaneContext(ctx);
    const size_t blocks = (voxels.size + ProjectedWindow::kBlock - 1) / ProjectedWindow::kBlock;
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, blocks, 1), ProjectionCounts{},
        [&](const tbb::blocked_range<size_t>& r, ProjectionCounts c) {
            SplatLanes lanes;
            PointLanes points;
            std::array<int64_t, kSplatLanes> slabs;  // of the group's voxels
            PendingProfiles profiles;                // --compositing slabs: the group's, in vectors
            LaneVoxels group;
            // The window's blocks [r.begin(), r.end()) (ProjectedWindow::kBlock voxels each), each
            // from the run that holds its first voxel on (the runs' sizes vary, 1 to 4 096). A
            // block's drawn primitives fill its slots from the front, in voxel order (compacted).
            size_t slot = 0, map = 0;  // the block's next free slot, and its next free exact-map slot
            // The group's voxels projected at once (their slabs, splats and points), then each stored
            // as the window's next primitive.
            const auto project = [&](const LaneView& batch) {
                if (batch.n == 0) return;
                profiles.flush(ctx.marginal, ctx.slabs.reach, window);
                slabsOf(batch.distance, batch.n, ctx.slabLength, voxels.slabBegin, voxels.slabEnd - 1, slabs.data());
                projectChunkInLanes(batch, laneContext, pointContext, lanes, points);
                for (size_t k = 0; k < batch.n; ++k) {
                    const size_t i = slot;  // taken below only if it is drawn (its order is set)
                    const int64_t slab = slabs[k];  // clamp(⌊distance / slabLength⌋, the window's slabs)
                    PrimitiveKind kind;
                    PixelRange range;
                    if (laneContext && lanes.status[k] != SplatLanes::kScalar) {
                        kind = storeLaneSplat(lanes, k, i, map, batch, slab, ctx, window, range);
                    } else if (pointContext && points.status[k] == PointLanes::kPoint) {
                        storeLanePoint(points, k, i, batch, slab, ctx, window, range);
                        kind = PrimitiveKind::Point;
                    } else {
                        Primitive p = projectVoxel(glm::dvec3(batch.viewPos[k]), batch.sigma[k], batch.color[k], ctx, batch.spread[k]);
                        p.members = batch.members[k];
                        p.depth = batch.distance[k];
                        p.slab = slab;
                        window.set(i, p, map);  // its profile below (set() writes p's default one first)
                        kind = p.kind, range = p.range;
                    }
                    if (kind == PrimitiveKind::Culled) continue;
                    const uint32_t members = batch.members[k];
                    ++(kind == PrimitiveKind::Point ? c.points : c.splats);
                    if (kind == PrimitiveKind::SplatExactIndex) ++c.exactIndexSplats;
                    c.drawnVoxels += members;
                    if (members > 1) ++c.lodAggregates, c.lodVoxels += members;
                    if (ctx.occlusion && !range.empty() && ctx.occlusion->hidden(range.x0, range.y0, range.x1, range.y1)) {
                        window.order[i] = ProjectedWindow::kNotDrawn;  // never binned: its profile is never read
                        ++(kind == PrimitiveKind::Point ? c.hidden.points : c.hidden.splats);
                        if (kind == PrimitiveKind::SplatExactIndex) ++c.hidden.exactIndexSplats;
                        c.hidden.voxels += members;
                        continue;
                    }
                    if (window.order[i] == ProjectedWindow::kNotDrawn) continue;  // no pixel: the slot is reused
                    ++slot;
                    map += window.records[i].hasExactMap;
                    if (ctx.slabs.on) {
                        const glm::dvec3 v(batch.viewPos[k]);
                        const float depthSpread = batch.depthSpread ? batch.depthSpread[k] : 0.f;
                        if (ctx.vector && ctx.marginal)
                            profiles.add(i, slabProfileInput(v, batch.distance[k], slab, depthSpread, ctx));
                        else
                            window.profile[i] = slabProfileFor(v, batch.distance[k], slab, depthSpread, ctx);
                    }
                }
            };
            const auto flushGroup = [&] {
                project(LaneView::of(group));
                group.n = 0;
            };
            const auto after = [](size_t k, const WindowSource& run) { return k < run.first + run.count; };
            for (size_t block = r.begin(); block < r.end(); ++block) {
                const size_t first = block * ProjectedWindow::kBlock, last = std::min(voxels.size, first + ProjectedWindow::kBlock);
                slot = map = first;
                for (auto run = std::upper_bound(voxels.sources.begin(), voxels.sources.end(), first, after);
                     run != voxels.sources.end() && run->first < last; ++run) {
                    const WindowSource& src = *run;
                    group.withDepthSpread = !src.records->depthSpread.empty();
                    const size_t from = std::max(first, src.first), to = std::min(last, src.first + src.count);
                    for (size_t i = src.begin + (from - src.first), end = src.begin + (to - src.first); i < end;) {
                        if (group.n == 0 && end - i >= kSplatLanes) {  // a whole lane group where it lies
                            project(LaneView::in(*src.records, i, kSplatLanes));
                            i += kSplatLanes;
                            continue;
                        }
                        const size_t take = std::min(end - i, kSplatLanes - group.n);
                        group.append(*src.records, i, take);
                        i += take;
                        if (group.n == kSplatLanes) flushGroup();
                    }
                }
                flushGroup();
                std::fill(window.order.begin() + ptrdiff_t(slot), window.order.begin() + ptrdiff_t(last), ProjectedWindow::kNotDrawn);
            }
            profiles.flush(ctx.marginal, ctx.slabs.reach, window);
            return c;
        },
        [](ProjectionCounts a, const ProjectionCounts& b) { return a += b; });
}

}  // namespace vdbsplat
