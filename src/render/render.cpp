// render/render.cpp — mode dispatch (see render.h).
#include "render/render.h"

#include <chrono>
#include <cstdio>
#include <memory>

#include "footprint/tables.h"
#include "render/hybrid.h"
#include "render/reference.h"
#include "shading/shading_field.h"
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

void checkVoxelBudget(const Volume& volume, const RenderSettings& settings) {
    if (volume.activeVoxels <= settings.maxActiveVoxels) return;
    throw Error(volume.file + ": grid '" + volume.name + "' has " + std::to_string(volume.activeVoxels) +
                " active voxels (active tiles counted voxel by voxel), more than the limit of " +
                std::to_string(settings.maxActiveVoxels) + " (raise it with --max-voxels, at most " +
                std::to_string(kHardMaxActiveVoxels) + ")");
}

/// Refuses an --eye so far from the grid that it covers less than a pixel and the depth
/// arithmetic of the renderers loses precision (10^6 bounding-box diagonals).
void checkEyeDistance(const CameraSpec& spec, const glm::dvec3& lo, const glm::dvec3& hi) {
    if (!spec.hasEye) return;
    const double diagonal = glm::length(hi - lo);
    const glm::dvec3 nearest = glm::clamp(spec.eye, lo, hi);
    const double distance = glm::length(spec.eye - nearest);
    const double limit = kMaxEyeDistanceInDiagonals * diagonal;
    if (!(distance <= limit)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "--eye: %.6g from the grid's bounds, more than %.0e times their diagonal (%.6g)",
                      distance, kMaxEyeDistanceInDiagonals, diagonal);
        throw Error(buf);
    }
}

Camera cameraFor(const Volume& volume, const RenderSettings& settings) {
    glm::dvec3 lo, hi;
    volume.worldBounds(lo, hi);
    checkEyeDistance(settings.camera, lo, hi);
    return makeCamera(settings.camera, lo, hi);
}

Image render(const Volume& volume, const TransferFunction& tf, const RenderSettings& settings, RenderStats& stats,
             const RenderControl& control) {
    const auto start = std::chrono::steady_clock::now();
    if (control.stop && control.stop()) throw RenderStopped("render stopped before it began");
    checkVoxelBudget(volume, settings);
    float lo, hi;
    normalizationRange(volume, lo, hi);
    const ClassificationTable table = tf.bake(lo, hi, volume.voxelSize);
    const Camera camera = cameraFor(volume, settings);
    stats.activeVoxels = volume.activeVoxels;
    // Shading (docs/shading.md): one VoxelShader for every mode. The reference reads each voxel
    // many times and takes the whole field, computed once; the forward modes shade the voxels
    // they draw as the stream classifies them.
    std::unique_ptr<VoxelShader> shader;
    if (settings.shading.active())
        shader = std::make_unique<VoxelShader>(volume, table, lo, hi, camera.eye(), settings.shading);
    // Emission (docs/emission.md): the attached grid's ε, added to every voxel after shading.
    std::unique_ptr<EmissionSource> emission;
    if (settings.emission.active()) emission = makeEmissionSource(volume, settings.emission);
    Image image;
    switch (settings.mode) {
        case RenderMode::Reference: {
            std::unique_ptr<ShadingField> field;
            if (shader) {
                field = std::make_unique<ShadingField>(*shader);
                stats.shadingSeconds = field->seconds();
            }
            image = renderReference(volume, table, camera, settings.spp, stats, field.get(), control, emission.get());
            break;
        }
        case RenderMode::Hybrid:
        case RenderMode::Splat:
        case RenderMode::Point: {
            const Tables tables =
                loadOrBuildTables(settings.tablesDir.empty() ? defaultTablesDir() : std::filesystem::path(settings.tablesDir));
            image = renderForward(volume, table, camera, tables, settings, stats, shader.get(), control, emission.get());
            break;
        }
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (control.progress) control.progress(1.0);
    return image;
}

}  // namespace vdbsplat
