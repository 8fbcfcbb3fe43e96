// render/hybrid.cpp — window-by-window forward resampling (see hybrid.h).
#include "render/hybrid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "composite/compositor.h"
#include "render/postfilter.h"
#include "render/project.h"
#include "volume/stream.h"

namespace vdbsplat {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// What the forward pipeline draws with, in the pixels of the image it composites on.
struct ForwardPass {
    double threshold;          ///< τ (px): projected voxel spacing below which voxels are points
    double lodPx;              ///< level-of-detail cell size (px)
    double prefilterVariance;  ///< V_h folded into each primitive (px²)
};

/// What one window's primitives draw, before the compositor's occlusion culling.
struct WindowCounts {
    uint64_t points = 0, splats = 0, exactIndexSplats = 0, lodAggregates = 0, lodVoxels = 0, drawnVoxels = 0;
    WindowCounts& operator+=(const WindowCounts& o) {
        points += o.points, splats += o.splats, exactIndexSplats += o.exactIndexSplats;
        lodAggregates += o.lodAggregates, lodVoxels += o.lodVoxels, drawnVoxels += o.drawnVoxels;
        return *this;
    }
};

/// Counts @p window in parallel (integer sums: the result does not depend on the split).
WindowCounts countWindow(std::span<const Primitive> window) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, window.size(), 16384), WindowCounts{},
        [&](const tbb::blocked_range<size_t>& r, WindowCounts c) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const Primitive& p = window[i];
                if (p.kind == PrimitiveKind::Culled) continue;
                ++(p.kind == PrimitiveKind::Point ? c.points : c.splats);
                if (p.kind == PrimitiveKind::SplatExactIndex) ++c.exactIndexSplats;
                c.drawnVoxels += p.members;
                if (p.members > 1) ++c.lodAggregates, c.lodVoxels += p.members;
            }
            return c;
        },
        [](WindowCounts a, const WindowCounts& b) { return a += b; });
}

/// Streams, projects and composites @p volume onto @p camera's pixels.
Image composite(const Volume& volume, const ClassificationTable& table, const Camera& camera, const Tables& tables,
                const RenderSettings& settings, const ForwardPass& pass, RenderStats& stats,
                const VoxelShader* shader, const RenderControl& control) {
    StreamOptions streamOptions = settings.stream;
    streamOptions.lodCellPx = pass.lodPx;
    streamOptions.pointBelowPx = settings.mode == RenderMode::Point   ? INFINITY
                                 : settings.mode == RenderMode::Splat ? 0.0
                                                                      : pass.threshold;
    VoxelStream stream(volume, camera, table, streamOptions, shader);
    TileCompositor compositor(camera.width(), camera.height(), tables,
                              ExactContext{&camera, volume.voxelSize, settings.simd, pass.prefilterVariance});
    const ProjectionContext ctx{camera,        tables,         volume.voxelSize,  stream.slabLength(),
                                settings.mode, pass.threshold, settings.footprint, settings.showPrimitives,
                                pass.prefilterVariance};
    const auto hidden = [&](int x0, int y0, int x1, int y1) { return compositor.hidden(x0, y0, x1, y1); };
    VoxelBatch batch;
    PrimitiveBuffer prims;
    uint64_t drawnVoxels = 0;
    while (true) {
        if (control.stop && control.stop()) throw RenderStopped("render stopped");
        if (control.progress) control.progress(stream.progress());
        auto t = Clock::now();
        if (!stream.next(batch, hidden)) break;
        stats.streamSeconds += since(t);
        t = Clock::now();
        const std::span<const Primitive> window = projectBatch(batch, ctx, prims);
        const WindowCounts counts = countWindow(window);
        stats.points += counts.points, stats.splats += counts.splats;
        stats.exactIndexSplats += counts.exactIndexSplats;
        stats.lodAggregates += counts.lodAggregates, stats.lodVoxels += counts.lodVoxels;
        drawnVoxels += counts.drawnVoxels;
        stats.projectSeconds += since(t);
        const SkippedPrimitives hiddenPrims = compositor.composite(window, stats.rasterizeSeconds, stats.compositeSeconds);
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
    return compositor.image();
}

}  // namespace

Image renderForward(const Volume& volume, const ClassificationTable& table, const Camera& camera,
                    const Tables& tables, const RenderSettings& settings, RenderStats& stats,
                    const VoxelShader* shader, const RenderControl& control) {
    if (settings.filterOrder == FilterOrder::Prefilter)
        return composite(volume, table, camera, tables, settings,
                         ForwardPass{settings.threshold, settings.lodPx, kPrefilterVariance}, stats, shader, control);
    // Postfilter: the same primitives (τ and the level of detail scaled to sub-pixels, so the
    // same voxels are points), composited at k× the resolution with only V_s folded in, then
    // the rest of the low-pass on the composited image (postfilter.h).
    const SubpixelGrid grid = makeSubpixelGrid(settings.subpixels, kPrefilterVariance);
    const Camera fine = subpixelCamera(camera, grid);
    const double k = grid.k;
    const Image sub = composite(volume, table, fine, tables, settings,
                                ForwardPass{settings.threshold * k, settings.lodPx * k, grid.fineVariance}, stats, shader, control);
    return postfilterImage(sub, grid, camera.width(), camera.height());
}

}  // namespace vdbsplat
