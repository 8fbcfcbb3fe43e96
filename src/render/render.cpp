// render/render.cpp — mode dispatch (see render.h).
#include "render/render.h"

#include <chrono>

#include "footprint/tables.h"
#include "render/hybrid.h"
#include "render/reference.h"
#include "util/error.h"

namespace vdbsplat {

void normalizationRange(const Volume& volume, float& lo, float& hi) {
    if (volume.valueMin >= 0.f && volume.valueMax <= 1.f) {
        lo = 0.f;
        hi = 1.f;
    } else {
        lo = volume.valueMin;
        hi = volume.valueMax > volume.valueMin ? volume.valueMax : volume.valueMin + 1.f;
    }
}

Camera cameraFor(const Volume& volume, const RenderSettings& settings) {
    glm::dvec3 lo, hi;
    volume.worldBounds(lo, hi);
    return makeCamera(settings.camera, lo, hi);
}

Image render(const Volume& volume, const TransferFunction& tf, const RenderSettings& settings, RenderStats& stats) {
    const auto start = std::chrono::steady_clock::now();
    float lo, hi;
    normalizationRange(volume, lo, hi);
    const ClassificationTable table = tf.bake(lo, hi, volume.voxelSize);
    const Camera camera = cameraFor(volume, settings);
    stats.activeVoxels = volume.activeVoxels;
    Image image;
    switch (settings.mode) {
        case RenderMode::Reference: image = renderReference(volume, table, camera, settings.spp, stats); break;
        case RenderMode::Hybrid:
        case RenderMode::Splat:
        case RenderMode::Point: {
            const Tables tables =
                loadOrBuildTables(settings.tablesDir.empty() ? defaultTablesDir() : std::filesystem::path(settings.tablesDir));
            image = renderForward(volume, table, camera, tables, settings, stats);
            break;
        }
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return image;
}

}  // namespace vdbsplat
