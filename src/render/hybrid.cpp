// render/hybrid.cpp — window-by-window forward resampling (see hybrid.h).
#include "render/hybrid.h"

#include <chrono>

#include "composite/compositor.h"
#include "render/project.h"
#include "volume/stream.h"

namespace vdbsplat {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

Image renderForward(const Volume& volume, const ClassificationTable& table, const Camera& camera,
                    const Tables& tables, const RenderSettings& settings, RenderStats& stats) {
    VoxelStream stream(volume, camera, table, settings.stream);
    TileCompositor compositor(camera.width(), camera.height(), tables, ExactContext{&camera, volume.voxelSize});
    const ProjectionContext ctx{camera,          tables,           volume.voxelSize,  stream.slabLength(),
                                settings.mode,   settings.threshold, settings.footprint, settings.showPrimitives};
    const auto hidden = [&](int x0, int y0, int x1, int y1) { return compositor.hidden(x0, y0, x1, y1); };
    VoxelBatch batch;
    std::vector<Primitive> prims;
    while (true) {
        auto t = Clock::now();
        if (!stream.next(batch, hidden)) break;
        stats.streamSeconds += since(t);
        t = Clock::now();
        projectBatch(batch, ctx, prims);
        for (const Primitive& p : prims) {
            if (p.kind == PrimitiveKind::Point) ++stats.points;
            else if (p.kind != PrimitiveKind::Culled) ++stats.splats;
            if (p.kind == PrimitiveKind::SplatExactIndex) ++stats.exactIndexSplats;
        }
        stats.projectSeconds += since(t);
        const SkippedPrimitives hiddenPrims = compositor.composite(prims, stats.rasterizeSeconds, stats.compositeSeconds);
        stats.points -= hiddenPrims.points;
        stats.splats -= hiddenPrims.splats;
        stats.exactIndexSplats -= hiddenPrims.exactIndexSplats;
    }
    // Everything else drew nothing: outside the frustum, behind opaque tiles, off screen,
    // or transparent under the transfer function.
    stats.culled = volume.activeVoxels - stats.points - stats.splats;
    stats.windows = stream.windows();
    stats.largestWindow = stream.largestWindow();
    return compositor.image();
}

}  // namespace vdbsplat
