// render/hybrid.cpp — window-by-window forward resampling (see hybrid.h).
#include "render/hybrid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>

#include "composite/compositor.h"
#include "footprint/kernel.h"
#include "footprint/pixel_box.h"
#include "render/forward_buffers.h"
#include "render/pending_tables.h"
#include "render/postfilter.h"
#include "render/project.h"
#include "volume/stream.h"

namespace vdbsplat {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Largest projected voxel spacing (sub-pixels) drawn as a point on a grid of k ≥ 2 sub-pixels.
constexpr double kMaxPointSpacingSubpx = 2.0;

/// What the forward pipeline draws with, in the pixels of the image it composites on.
struct ForwardPass {
    double threshold;          ///< τ (px): projected voxel spacing below which voxels are points
    double lodPx;              ///< level-of-detail cell size (px)
    double lodCoarsePx;        ///< its second cap, for 4³ and 8³ cells (px; RenderSettings::lodCoarsePx)
    double prefilterVariance;  ///< V_h folded into each minified primitive (px²)
    double magnifiedPrefilterVariance;  ///< and into magnified ones (the ramp's end; footprint/prefilter.h)
    /// The low-pass the level-of-detail rule weighs an aggregate's spread against (px²; volume/stream.h):
    /// prefilterVariance, except on a grid of k sub-pixels, where it is V_s·k. With V_s alone the
    /// grid draws far finer aggregates than the pixel grid (16× the points at the far checker box,
    /// k = 2: 2.7× the time); with V_s·k², the pixel grid's cells, it loses what k = 2 gained
    /// (checker box, Phong, far, 400², against the reference: V_s 57.4 dB in 0.112 s, V_s·k 56.1 dB
    /// in 0.068 s, V_s·k² 54.5 dB in 0.037 s; Engine 69.4 / 71.1 / 64.2 dB in 0.107 / 0.067 / 0.066 s;
    /// tubes 57.4 / 61.1 / –; docs/shading.md, session 7).
    double lodPrefilterVariance;
};

/// What becomes of the composited frame: the output image made from it in place (copied, or
/// postfiltered, into the image's data window), while the compositor still holds it.
using FrameSink = std::function<WindowedImage(const FrameView&)>;

/// Streams, projects and composites @p volume onto @p camera's pixels; returns @p sink's image of the frame.
WindowedImage composite(const Volume& volume, const ClassificationTable& table, const Camera& camera,
                        PendingTables& pending, const RenderSettings& settings, const ForwardPass& pass,
                        RenderStats& stats, const VoxelShader* shader, const RenderControl& control,
                        const EmissionSource* emission, const FrameSink& sink) {
    // The kernels' shape in view space (anisotropic or sheared voxels: ellipsoids).
    // view = R·(world − eye), R's rows right, up, forward: M = R·A.
    const glm::dmat3 worldToView = glm::transpose(glm::dmat3(camera.right(), camera.up(), camera.forward()));
    VoxelShape shape = VoxelShape::of(worldToView * glm::dmat3(volume.indexToWorld));
    shape.sphere = volume.isotropic;
    StreamOptions streamOptions = settings.stream;
    streamOptions.slabThickness = settings.effectiveSlabThickness();
    const bool slabOrder = settings.effectiveCompositing() == CompositingOrder::Slabs;
    streamOptions.depthSpread = slabOrder;  // the slab order's aggregate profiles read it
    // The slab order's automatic thickness (½ voxel) is widened for elongated kernels so that a
    // kernel spans at most 2·kMaxSlabReach slabs (R·sMax ≤ K·slab): voxels 1×1×2.5 get 0.92.
    if (slabOrder && settings.slabThickness == 0.0)
        streamOptions.slabThickness = std::max(streamOptions.slabThickness,
                                               pending.kernel().radius() * shape.sMax / (kMaxSlabReach * volume.voxelSize));
    // Windows of the same depth whatever the slab: 8 voxels' worth of slabs (the window's voxel
    // bounds still narrow it; windows split only at slab boundaries, so the image is the same).
    streamOptions.slabsPerWindow = int(std::lround(streamOptions.slabsPerWindow / streamOptions.slabThickness));
    streamOptions.lodCellPx = pass.lodPx;
    streamOptions.lodCoarseCellPx = pass.lodCoarsePx;
    streamOptions.keepMoments = control.buffers && control.buffers->keepMoments;  // bench, animate, study, --warmup
    streamOptions.lodBlend = settings.effectiveLodBlend();
    streamOptions.pointPrefilterVariance = pass.lodPrefilterVariance;
    streamOptions.pointBelowPx = settings.mode == RenderMode::Point ? INFINITY
                                 : drawsOnlySplats(settings.mode)   ? 0.0
                                                                    : pass.threshold;
    ForwardBuffers own;  // used only when the caller keeps none (empty until then: no allocation)
    ForwardBuffers& buffers = control.buffers ? *control.buffers : own;
    VoxelStream stream(volume, camera, table, streamOptions, shader, emission, &buffers.stream);
    ExactContext exact{&camera, volume.voxelSize, settings.simd};
    exact.lowPass = PrefilterRamp(pass.prefilterVariance, pass.magnifiedPrefilterVariance);  // = ctx.lowPass()
    exact.shape = &shape;
    // --compositing slabs: a kernel reaches R·(its longest semi-axis per index unit) along any
    // ray, so K = ⌈R·sMax / slab length⌉ slabs on either side of its own (2 for cubic voxels).
    SlabCompositing slabs;
    if (slabOrder) {
        slabs.on = true;
        slabs.reach = slabReachFor(pending.kernel().radius() * shape.sMax / stream.slabLength());
    }
    const Tables& tables = pending.get();  // read meanwhile (render/pending_tables.h)
    // One colour channel where every primitive's colour is grey: the table's, shaded or not (white
    // light: c·D + S, the same operations on each channel), without emission or the splats' tint
    // (ColorChannels; the same image).
    const bool grey = settings.greyChannel && table.grey() && !emission && !settings.showPrimitives;
    TileCompositor compositor(camera.width(), camera.height(), tables, exact, slabs, &buffers.compositor,
                              grey ? ColorChannels::Grey : ColorChannels::Rgb, float(settings.cutoff));
    stats.compositedChannels = compositor.channels();
    ProjectionContext ctx{camera,        tables,         volume.voxelSize,  stream.slabLength(),
                          settings.mode, pass.threshold, settings.footprint, settings.showPrimitives,
                          pass.prefilterVariance};
    ctx.magnifiedPrefilterVariance = pass.magnifiedPrefilterVariance;
    ctx.shape = &shape;
    ctx.occlusion = &compositor;
    ctx.vector = settings.simd;
    ctx.slabs = slabs;
    std::optional<MarginalCdfTable> marginal;
    if (slabs.on) ctx.marginal = &marginal.emplace(*tables.kernel);
    const auto hidden = [&](int x0, int y0, int x1, int y1) { return compositor.hidden(x0, y0, x1, y1); };
    const auto partlyHidden = [&](int x0, int y0, int x1, int y1) { return compositor.partlyHidden(x0, y0, x1, y1); };
    StreamWindow& voxels = buffers.voxels;
    ProjectedWindow& window = buffers.window;
    uint64_t drawnVoxels = 0;
    while (true) {
        if (control.stop && control.stop()) throw RenderStopped("render stopped");
        if (control.progress) control.progress(stream.progress());
        auto t = Clock::now();
        if (!stream.next(voxels, hidden, partlyHidden)) break;
        stats.streamSeconds += since(t);
        t = Clock::now();
        const ProjectionCounts counts = projectWindow(voxels, ctx, window);
        stats.points += counts.points, stats.splats += counts.splats;
        stats.exactIndexSplats += counts.exactIndexSplats;
        stats.lodAggregates += counts.lodAggregates, stats.lodVoxels += counts.lodVoxels;
        drawnVoxels += counts.drawnVoxels;
        stats.projectSeconds += since(t);
        SkippedPrimitives hiddenPrims = compositor.composite(window, stats.rasterizeSeconds, stats.compositeSeconds);
        hiddenPrims.points += counts.hidden.points, hiddenPrims.splats += counts.hidden.splats;
        hiddenPrims.exactIndexSplats += counts.hidden.exactIndexSplats, hiddenPrims.voxels += counts.hidden.voxels;
        stats.points -= hiddenPrims.points;
        stats.splats -= hiddenPrims.splats;
        stats.exactIndexSplats -= hiddenPrims.exactIndexSplats;
        drawnVoxels -= hiddenPrims.voxels;
        stats.culledHidden += hiddenPrims.voxels;
    }
    // Everything else drew nothing: outside the frustum, behind opaque tiles, off screen,
    // or transparent under the transfer function.
    stats.culled = volume.activeVoxels - std::min<uint64_t>(volume.activeVoxels, drawnVoxels);
    stats.culledFrustum = stream.counts().frustum;
    stats.culledOccluded = stream.counts().occluded;
    stats.windows = stream.windows();
    stats.largestWindow = stream.largestWindow();
    stats.compositedPixels = uint64_t(camera.width()) * uint64_t(camera.height());
    auto t = Clock::now();
    compositor.finish();
    stats.compositeSeconds += since(t);
    return sink(compositor.frame());
}

/// How far (px) past the projection of a primitive's kernel sphere its deposits reach: a point's
/// filter r_s ≤ kPointMaxRadiusPx (pointfilter/point_filter.h); a splat's support ellipse
/// widened by V (screen_kernel.cpp: a' = √(a² + (R/s_g)²·V) ≤ a + (R/s_g)·√V); one pixel to spare.
double depositReachPx(double prefilterVariance, const KernelShape& kernel) {
    return std::max(kPointMaxRadiusPx, kernel.radius() / kernel.sigma() * std::sqrt(prefilterVariance)) + 1.0;
}

/// The pixels of @p camera any primitive of @p volume can touch, grown by @p grow pixels: the
/// projection of the active voxels' index box widened by the kernel radius (R + ½ voxel; it
/// holds every voxel's kernel sphere, and a convex set in front of the eye projects inside
/// its corners' hull), plus the deposits' reach. Nothing when a corner is at or behind the
/// eye plane (no crop), or when the rectangle is the whole image.
std::optional<PixelRange> coveredPixels(const Volume& volume, const Camera& camera, const RenderSettings& settings,
                                        double reachPx, int grow) {
    if (!settings.cropToVolume) return std::nullopt;
    const openvdb::CoordBBox& box = volume.indexBox;
    const double r = Kernel::kRadius + 0.5;
    PixelBox hull;
    hull.lo = PixelCoord(INFINITY), hull.hi = PixelCoord(-INFINITY);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 idx(corner & 1 ? box.max().x() + r : box.min().x() - r,
                             corner & 2 ? box.max().y() + r : box.min().y() - r,
                             corner & 4 ? box.max().z() + r : box.min().z() - r);
        const ViewPoint v = camera.toView(glm::dvec3(volume.indexToWorld * glm::dvec4(idx, 1.0)));
        if (!(v.z > 1e-6 * glm::length(v))) return std::nullopt;
        const PixelCoord p = camera.project(v);
        hull.lo = glm::min(hull.lo, p), hull.hi = glm::max(hull.hi, p);
    }
    const double m = reachPx + grow;
    hull.lo -= m, hull.hi += m;
    const PixelRange range = pixelRange(hull, camera.width(), camera.height());
    if (range.x0 == 0 && range.y0 == 0 && range.x1 == camera.width() - 1 && range.y1 == camera.height() - 1)
        return std::nullopt;
    return range;
}

/// τ on a grid of @p k sub-pixels per pixel: the same voxels are points as on the pixel grid
/// (τ·k sub-pixels), but no more than kMaxPointSpacingSubpx sub-pixels apart: a point's filter
/// (V = V_s + (s_g·s)², point_filter.h) must fit its 7×7 window, which a 3-sub-pixel voxel's does
/// not (σ = 2 sub-pixels, cut at 1.75σ and renormalised: the points ripple; checker box, Phong,
/// distance 2, 400²: 49.8 dB at k = 4 against 67.0 at k = 2, 70.3 with the cap). A τ the user set
/// above the cap on the pixel grid (k = 1) is kept.
double subpixelThreshold(double threshold, int k) {
    if (k == 1) return threshold;
    return std::min(threshold * k, std::max(threshold, kMaxPointSpacingSubpx));
}

/// A @p width × @p height image for a sink that writes every pixel of it: the caller's recycled
/// memory (ForwardBuffers::takeImage), or a new image.
Image sinkImage(const RenderControl& control, int width, int height) {
    return control.buffers ? control.buffers->takeImage(width, height) : Image(width, height);
}

/// A @p width × @p height image, transparent (T = 1, no radiance) except for @p frame at (@p x0, @p y0):
/// its data window, the frame's rows copied in parallel (into sinkImage's memory).
WindowedImage placed(const FrameView& frame, int x0, int y0, int width, int height, const RenderControl& control) {
    Image window = sinkImage(control, frame.width, frame.height);
    adviseRowsWritten(window, 0, frame.height, frame.width);
    tbb::parallel_for(tbb::blocked_range<int>(0, frame.height, 16), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y)
            for (int x = 0; x < frame.width; ++x) window.at(x, y) = frame.at(x, y);
    });
    return WindowedImage(std::move(window), x0, y0, width, height);
}

}  // namespace

WindowedImage renderForward(const Volume& volume, const ClassificationTable& table, const Camera& camera,
                            PendingTables& tables, const RenderSettings& settings, RenderStats& stats,
                            const VoxelShader* shader, const RenderControl& control, const EmissionSource* emission) {
    // Fixed costs follow the pixels the volume covers, not the image: the compositor, its
    // tiles and the postfilter see only that rectangle (a cropped camera: the same rays, so the
    // same image there, up to the float rounding of pixel coordinates), and the image stores only
    // it (its data window); the rest is empty.
    // Ewa and Swan fold V_h into each primitive by definition (the prefilter order); None has no
    // low-pass at all, and no level of detail (an aggregate is a prefiltered point).
    if (settings.filterOrder == FilterOrder::Prefilter || modeFixesFilterOrder(settings.mode)) {
        const bool none = settings.mode == RenderMode::None;
        const double v = none ? 0.0 : kPrefilterVariance;
        const ForwardPass pass{settings.threshold, none ? 0.0 : settings.lodPx, none ? 0.0 : settings.effectiveLodCoarsePx(), v, v, v};
        const std::optional<PixelRange> crop = coveredPixels(volume, camera, settings, depositReachPx(pass.prefilterVariance, tables.kernel()), 0);
        const auto at = [&](int x0, int y0) {
            return [&camera, &control, x0, y0](const FrameView& f) {
                return placed(f, x0, y0, camera.width(), camera.height(), control);
            };
        };
        if (!crop) return composite(volume, table, camera, tables, settings, pass, stats, shader, control, emission, at(0, 0));
        const int w = crop->x1 - crop->x0 + 1, h = crop->y1 - crop->y0 + 1;
        return composite(volume, table, camera.cropped(crop->x0, crop->y0, w, h), tables, settings, pass, stats, shader,
                         control, emission, at(crop->x0, crop->y0));
    }
    // Postfilter: the same primitives (τ and the level of detail scaled to sub-pixels, so the
    // same voxels are points), composited at k× the resolution with only V_s folded in, then
    // the rest of the low-pass on the composited image (postfilter.h).
    const SubpixelGrid grid = makeSubpixelGrid(settings.subpixels, kPrefilterVariance);
    const Camera fine = subpixelCamera(camera, grid);
    const int k = grid.k;
    const ForwardPass pass{subpixelThreshold(settings.threshold, k), settings.lodPx * k, settings.effectiveLodCoarsePx() * k, grid.fineVariance,
                           grid.magnifiedVariance, grid.fineVariance * k};
    // Deposits reach depositReachPx sub-pixels (≤ that many pixels) past the kernels; the output
    // pixels they reach through the filter lie within `border` more; the crop of the sub-pixel
    // image is that output rectangle with its own border, as subpixelCamera frames the whole image.
    const std::optional<PixelRange> crop =
        coveredPixels(volume, camera, settings, depositReachPx(pass.prefilterVariance, tables.kernel()), grid.border);
    // The postfilter reads the compositor's frame and writes the output image's data window.
    const auto filtered = [&](int x0, int y0, int w, int h) {
        return [&camera, &grid, &control, x0, y0, w, h](const FrameView& f) {
            Image window = sinkImage(control, w, h);  // postfilterInto writes every pixel
            postfilterInto(f, grid, w, h, window, 0, 0);
            return WindowedImage(std::move(window), x0, y0, camera.width(), camera.height());
        };
    };
    if (!crop)
        return composite(volume, table, fine, tables, settings, pass, stats, shader, control, emission,
                         filtered(0, 0, camera.width(), camera.height()));
    const int w = crop->x1 - crop->x0 + 1, h = crop->y1 - crop->y0 + 1;
    const Camera fineCrop = fine.cropped(k * crop->x0, k * crop->y0, k * (w + 2 * grid.border), k * (h + 2 * grid.border));
    return composite(volume, table, fineCrop, tables, settings, pass, stats, shader, control, emission,
                     filtered(crop->x0, crop->y0, w, h));
}

}  // namespace vdbsplat
