// render/project_modes.cpp — the study modes' primitives (see project_modes.h).
#include "render/project_modes.h"

#include <cmath>

#include "footprint/ewa.h"
#include "footprint/kernel.h"
#include "footprint/swan.h"
#include "render/project.h"

namespace vdbsplat {

void fillEwaSplat(Primitive& p, const glm::dvec3& c, float sigma, const ProjectionContext& ctx) {
    const EwaKernel k =
        makeEwaKernel(ctx.camera, c, ctx.voxelSize, ctx.tables.kernel->sigma(), ctx.tables.kernel->radius(),
                      ctx.prefilterVariance);  // EWA's filter order is fixed: its ramp is flat
    if (!(k.amplitude > 0.0)) {
        p.kind = PrimitiveKind::Culled;
        return;
    }
    p.kind = PrimitiveKind::Splat;
    p.centre = glm::vec2(k.centre);
    p.conic = glm::vec3(k.conic[0][0], k.conic[0][1], k.conic[1][1]);
    p.scale = float(sigma * k.amplitude);  // σ·h·amplitude with σ per world unit = sigma/h
    p.sin2Alpha = 0.f;                     // α = 0 row: d² = i², the affine index is the footprint's index
    p.range = pixelRange(k.bounds, ctx.camera.width(), ctx.camera.height());
}

bool keepsTablePath(double spacingPx, const ProjectionContext& ctx) {
    return ctx.mode == RenderMode::Swan && spacingPx < ctx.threshold;
}

ScreenKernel splatKernelFor(const SphereProjection& sphere, double spacingPx, double lowPass, const ProjectionContext& ctx) {
    if (keepsTablePath(spacingPx, ctx)) return makeSwanKernel(sphere, lowPass, *ctx.tables.kernel);
    return makeScreenKernel(sphere, lowPass, *ctx.tables.kernel);
}

void snapToNearestPixel(Primitive& p, int width, int height) {
    const int x = int(std::floor(p.centre.x)), y = int(std::floor(p.centre.y));
    p.centre = glm::vec2(float(x) + 0.5f, float(y) + 0.5f);
    p.variance = float(kNearestPixelVariance);
    if (x < 0 || y < 0 || x >= width || y >= height) {
        p.kind = PrimitiveKind::Culled;
        p.range = {};
        return;
    }
    p.range = PixelRange{x, y, x, y};
}

}  // namespace vdbsplat
