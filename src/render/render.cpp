// render/render.cpp — mode dispatch (see render.h).
#include "render/render.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "footprint/tables.h"
#include "render/forward_buffers.h"
#include "render/hybrid.h"
#include "render/pending_tables.h"
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

/// Ellipsoid kernels (non-cubic or sheared voxels, docs/kernel.md §10) are projected exactly for
/// the standard kernel; the study's affine EWA and Swan footprints and the second kernel are
/// defined for spheres only, so those combinations are refused rather than drawn as something else.
void checkKernelShape(const Volume& volume, const RenderSettings& settings) {
    if (volume.isotropic) return;
    const std::string where = volume.file + ": grid '" + volume.name + "' has non-cubic or sheared voxels";
    if (settings.mode == RenderMode::Ewa || settings.mode == RenderMode::Swan)
        throw Error("--mode " + toString(settings.mode) + ": " + where + ", which it does not support (use hybrid, splat, point, none or reference)");
    if (&KernelShape::named(settings.kernel) != &KernelShape::standard())
        throw Error("--kernel " + settings.kernel + ": " + where + ", which only the standard kernel supports");
}

Camera cameraFor(const Volume& volume, const RenderSettings& settings) {
    glm::dvec3 lo, hi;
    volume.worldBounds(lo, hi);
    checkEyeDistance(settings.camera, lo, hi);
    return makeCamera(settings.camera, lo, hi);
}

bool everyVoxelMinified(const Volume& volume, const Camera& camera, double thresholdPx) {
    if (volume.indexBox.empty()) return false;
    const openvdb::CoordBBox& box = volume.indexBox;
    double zNear = INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 idx(corner & 1 ? box.max().x() : box.min().x(), corner & 2 ? box.max().y() : box.min().y(),
                             corner & 4 ? box.max().z() : box.min().z());
        zNear = std::min(zNear, camera.toView(glm::dvec3(volume.indexToWorld * glm::dvec4(idx, 1.0))).z);
    }
    // The depth is linear over the box, so its least value is at a corner.
    return zNear > 0.0 && volume.largestAxis() * camera.focal() / zNear < thresholdPx;
}

RenderSettings resolvedFor(const Volume& volume, const Camera& camera, RenderSettings settings) {
    if (settings.subpixels == kAutoSubpixels)
        settings.subpixels = settings.effectiveSubpixels(everyVoxelMinified(volume, camera, settings.threshold));
    return settings;
}

namespace {
/// Minor page faults of the process so far (0 where getrusage fails).
uint64_t minorPageFaults() {
    rusage usage{};
    return getrusage(RUSAGE_SELF, &usage) == 0 ? uint64_t(usage.ru_minflt) : 0;
}
}  // namespace

WindowedImage renderWindowed(const Volume& volume, const TransferFunction& tf, const RenderSettings& requested,
                             RenderStats& stats, const RenderControl& control) {
    const auto start = std::chrono::steady_clock::now();
    const uint64_t faultsBefore = minorPageFaults();
    if (control.stop && control.stop()) throw RenderStopped("render stopped before it began");
    checkVoxelBudget(volume, requested);
    checkKernelShape(volume, requested);
    // The forward modes' tables are read on a worker while this thread bakes the transfer
    // function and renderForward sets up the stream (render/pending_tables.h).
    // Kept buffers lend the tables an earlier render read, for the same directory and kernel.
    std::optional<PendingTables> tables;
    const std::filesystem::path tablesDir = requested.tablesDir.empty() ? defaultTablesDir() : std::filesystem::path(requested.tablesDir);
    ForwardBuffers* kept = control.buffers;
    if (requested.mode != RenderMode::Reference) {
        const KernelShape& kernel = KernelShape::named(requested.kernel);
        if (kept && kept->tables && kept->tables->dir == tablesDir && kept->tables->kernel == &kernel)
            tables.emplace(kept->tables->tables, kernel);
        else
            tables.emplace(tablesDir, kernel);
    }
    float lo, hi;
    normalizationRange(volume, lo, hi);
    const ClassificationTable table = tf.bake(lo, hi, volume.voxelSize);
    const Camera camera = cameraFor(volume, requested);
    const RenderSettings settings = resolvedFor(volume, camera, requested);
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
    WindowedImage image;
    switch (settings.mode) {
        case RenderMode::Reference: {
            std::unique_ptr<ShadingField> field;
            if (shader) {
                field = std::make_unique<ShadingField>(*shader);
                stats.shadingSeconds = field->seconds();
            }
            image = WindowedImage(renderReference(volume, table, camera, settings.spp, stats, field.get(), control,
                                                  emission.get(), KernelShape::named(settings.kernel)));
            break;
        }
        case RenderMode::Hybrid:
        case RenderMode::Splat:
        case RenderMode::Point:
        case RenderMode::Ewa:
        case RenderMode::Swan:
        case RenderMode::None: {
            image = renderForward(volume, table, camera, *tables, settings, stats, shader.get(), control, emission.get());
            if (kept) kept->tables = ForwardBuffers::KeptTables{tablesDir, &tables->kernel(), tables->shared()};
            break;
        }
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const uint64_t faultsAfter = minorPageFaults();
    stats.pageFaults = faultsAfter > faultsBefore ? faultsAfter - faultsBefore : 0;
    if (control.progress) control.progress(1.0);
    return image;
}

Image render(const Volume& volume, const TransferFunction& tf, const RenderSettings& settings, RenderStats& stats,
             const RenderControl& control) {
    const auto start = std::chrono::steady_clock::now();
    const uint64_t faultsBefore = minorPageFaults();
    Image image = renderWindowed(volume, tf, settings, stats, control).full();
    // The whole image is this render's output: its time and page faults count (renderWindowed's
    // include neither).
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const uint64_t faultsAfter = minorPageFaults();
    stats.pageFaults = faultsAfter > faultsBefore ? faultsAfter - faultsBefore : 0;
    return image;
}

}  // namespace vdbsplat
