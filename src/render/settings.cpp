// render/settings.cpp — validation and JSON echo of the render settings.
#include "render/settings.h"

#include <cmath>
#include <filesystem>

#include "footprint/kernel.h"
#include "util/error.h"

namespace vdbsplat {

RenderMode parseRenderMode(const std::string& name) {
    if (name == "hybrid") return RenderMode::Hybrid;
    if (name == "splat") return RenderMode::Splat;
    if (name == "point") return RenderMode::Point;
    if (name == "ewa") return RenderMode::Ewa;
    if (name == "swan") return RenderMode::Swan;
    if (name == "none") return RenderMode::None;
    if (name == "reference") return RenderMode::Reference;
    throw Error("--mode: unknown mode '" + name + "' (choose " + kRenderModeNames + ")");
}

std::string toString(RenderMode mode) {
    switch (mode) {
        case RenderMode::Hybrid: return "hybrid";
        case RenderMode::Splat: return "splat";
        case RenderMode::Point: return "point";
        case RenderMode::Ewa: return "ewa";
        case RenderMode::Swan: return "swan";
        case RenderMode::None: return "none";
        case RenderMode::Reference: return "reference";
    }
    return "?";
}

bool drawsOnlySplats(RenderMode mode) {
    return mode == RenderMode::Splat || mode == RenderMode::Ewa || mode == RenderMode::Swan;
}

bool modeFixesFilterOrder(RenderMode mode) {
    return mode == RenderMode::Ewa || mode == RenderMode::Swan || mode == RenderMode::None;
}

void RenderSettings::validate() const {
    constexpr int kMaxSide = 16384;
    if (camera.width < 1 || camera.height < 1 || camera.width > kMaxSide || camera.height > kMaxSide)
        throw Error("--size: each side must be in [1, " + std::to_string(kMaxSide) + "]");
    if (!(camera.fovDeg > 0.0 && camera.fovDeg < 170.0)) throw Error("--fov: must be in (0, 170) degrees");
    if (!(std::isfinite(camera.distance) && camera.distance > 0.0 && camera.distance < 1e6))
        throw Error("--distance: must be a positive number");
    if (threads < 0 || threads > 1024) throw Error("--threads: must be in [0, 1024]");
    if (spp < 1 || spp > 1024) throw Error("--spp: must be in [1, 1024]");
    if (!(std::isfinite(threshold) && threshold > 0.0)) throw Error("--threshold: must be a positive number of pixels");
    if (!(cutoff >= kMinCutoff && cutoff <= kMaxCutoff))
        throw Error("--cutoff: must be a transmittance in [1e-6, 0.05]");
    if (!(std::isfinite(lodPx) && lodPx >= 0.0 && lodPx <= 64.0))
        throw Error("--lod: must be a number of pixels in [0, 64] (0 turns level of detail off)");
    if (lodCoarsePx != 0.0 && !(std::isfinite(lodCoarsePx) && lodCoarsePx >= lodPx && lodCoarsePx <= 64.0))
        throw Error("--lod: the second cap (PX,PX2) must be a number of pixels in [PX, 64]");
    if ((subpixels < 1 && subpixels != kAutoSubpixels) || subpixels > kMaxSubpixels)
        throw Error("--subpixels: must be 'auto' or in [1, " + std::to_string(kMaxSubpixels) + "]");
    if (maxActiveVoxels < 1 || maxActiveVoxels > kHardMaxActiveVoxels)
        throw Error("--max-voxels: must be in [1, " + std::to_string(kHardMaxActiveVoxels) + "]");
    if (!(slabThickness == 0.0 || (slabThickness >= 0.5 && slabThickness <= 1.0)))
        throw Error("--slab-thickness: must be a number of voxels in [0.5, 1]");
    shading.validate();
    emission.validate();
    (void)KernelShape::named(kernel);  // throws "--kernel: unknown kernel ..."
    if (!tablesDir.empty()) {
        std::error_code ec;
        if (!std::filesystem::is_directory(tablesDir, ec))
            throw Error("--tables: " + tablesDir + ": " +
                        (std::filesystem::exists(tablesDir, ec) ? "not a directory" : "no such directory"));
    }
}

FootprintPath parseFootprintPath(const std::string& name) {
    if (name == "auto") return FootprintPath::Auto;
    if (name == "table") return FootprintPath::Table;
    if (name == "exact") return FootprintPath::Exact;
    throw Error("--footprint: expected 'auto', 'table' or 'exact', got '" + name + "'");
}

std::string toString(FootprintPath path) {
    switch (path) {
        case FootprintPath::Table: return "table";
        case FootprintPath::Auto: return "auto";
        case FootprintPath::Exact: return "exact";
    }
    return "?";
}

FilterOrder parseFilterOrder(const std::string& name) {
    if (name == "prefilter") return FilterOrder::Prefilter;
    if (name == "postfilter") return FilterOrder::Postfilter;
    throw Error("--filter-order: expected 'prefilter' or 'postfilter', got '" + name + "'");
}

std::string toString(FilterOrder order) { return order == FilterOrder::Prefilter ? "prefilter" : "postfilter"; }

std::optional<CompositingOrder> parseCompositingOrder(const std::string& name) {
    if (name == "auto") return std::nullopt;
    if (name == "kernels") return CompositingOrder::Kernels;
    if (name == "slabs") return CompositingOrder::Slabs;
    throw Error("--compositing: expected 'auto', 'kernels' or 'slabs', got '" + name + "'");
}

std::optional<LodBlend> parseLodBlend(const std::string& name) {
    if (name == "auto") return std::nullopt;
    if (name == "on") return LodBlend::On;
    if (name == "off") return LodBlend::Off;
    if (name == "still") return LodBlend::Still;
    throw Error("--lod-blend: expected 'auto', 'on', 'off' or 'still', got '" + name + "'");
}

std::string toString(LodBlend blend) {
    return blend == LodBlend::On ? "on" : blend == LodBlend::Off ? "off" : "still";
}

std::string toString(CompositingOrder order) { return order == CompositingOrder::Slabs ? "slabs" : "kernels"; }

namespace {
/// RenderSettings::toJson (@p everyDefault false) and identityJson (true): the settings that older
/// outputs left out at their defaults (RenderSettings::kIdentityOnlyKeys) are written always, or
/// only away from their defaults; the one place each key's rule is written.
nlohmann::json settingsJson(const RenderSettings& s, bool everyDefault) {
    const RenderMode mode = s.mode;
    const auto& camera = s.camera;
    const bool forward = mode != RenderMode::Reference;  // the reference has no cutoff, slabs or levels
    nlohmann::json j;
    j["mode"] = toString(mode);
    j["width"] = camera.width;
    j["height"] = camera.height;
    j["fov"] = camera.fovDeg;
    if (camera.hasEye) {
        j["eye"] = {camera.eye.x, camera.eye.y, camera.eye.z};
        j["look_at"] = {camera.lookAt.x, camera.lookAt.y, camera.lookAt.z};
        j["up"] = {camera.up.x, camera.up.y, camera.up.z};
    } else {
        j["distance"] = camera.distance;
        if (camera.hasViewDir) {
            j["view_dir"] = {camera.viewDir.x, camera.viewDir.y, camera.viewDir.z};
            j["up"] = {camera.up.x, camera.up.y, camera.up.z};
        }
    }
    j["tf"] = s.transferFunction;
    j["grid"] = s.gridName;
    j["spp"] = s.spp;
    j["threshold"] = s.threshold;
    if (forward && (everyDefault || s.cutoff != kDefaultCutoff)) j["cutoff"] = s.cutoff;
    j["footprint"] = toString(s.footprint);
    j["kernel"] = s.kernel;
    // Ewa and Swan filter each primitive, None filters nothing (RenderMode): echo what was used.
    j["filter_order"] = mode == RenderMode::None ? "none" : modeFixesFilterOrder(mode) ? "prefilter" : toString(s.filterOrder);
    // "auto" only where nothing resolved it for a view (render.h resolvedFor does).
    if (modeFixesFilterOrder(mode)) j["subpixels"] = 1;
    else if (s.subpixels == kAutoSubpixels) j["subpixels"] = "auto";
    else j["subpixels"] = s.subpixels;
    j["show_primitives"] = s.showPrimitives;
    j["lod"] = mode == RenderMode::None ? 0.0 : s.lodPx;
    const double lodCoarse = mode == RenderMode::None ? 0.0 : s.effectiveLodCoarsePx();
    if (forward && (everyDefault || lodCoarse > s.lodPx)) j["lod_coarse"] = lodCoarse;  // one cap: absent
    if (forward && mode != RenderMode::None) j["lod_blend"] = toString(s.effectiveLodBlend());
    const CompositingOrder order = s.effectiveCompositing();
    if (forward && (everyDefault || order != CompositingOrder::Kernels)) j["compositing"] = toString(order);
    if (forward && (everyDefault || s.effectiveSlabThickness() != 1.0)) j["slab_thickness"] = s.effectiveSlabThickness();
    j["simd"] = s.simd;
    j["tables"] = s.tablesDir;  // "": the shipped tables (or built in memory where absent)
    if (s.shading.active()) j["shading"] = s.shading.toJson();  // absent when off: unshaded outputs unchanged
    if (s.emission.active()) j["emission"] = s.emission.toJson();  // likewise
    return j;
}
}  // namespace

nlohmann::json RenderSettings::toJson() const { return settingsJson(*this, false); }

nlohmann::json RenderSettings::identityJson() const { return settingsJson(*this, true); }

nlohmann::json RenderStats::toJson() const {
    nlohmann::json j;
    j["seconds"] = seconds;
    j["active_voxels"] = activeVoxels;
    j["points"] = points;
    j["splats"] = splats;
    j["culled"] = culled;
    j["culled_by"] = {{"frustum", culledFrustum}, {"occluded_blocks", culledOccluded},
                      {"hidden_at_tiles", culledHidden},
                      {"other", culled - std::min(culled, culledFrustum + culledOccluded + culledHidden)}};
    j["lod_aggregates"] = lodAggregates;
    j["lod_voxels"] = lodVoxels;
    j["splats_exact_index"] = exactIndexSplats;
    j["windows"] = windows;
    if (compositedChannels > 0) j["composited_channels"] = compositedChannels;
    j["largest_window_voxels"] = largestWindow;
    if (compositedPixels) j["composited_pixels"] = compositedPixels;
    j["page_faults"] = pageFaults;
    const uint64_t drawn = points + splats;
    j["splat_fraction"] = drawn ? double(splats) / double(drawn) : 0.0;
    if (rays) j["rays"] = rays;
    if (raysPerPixel) j["rays_per_pixel"] = raysPerPixel;
    j["stage_seconds"] = {{"stream", streamSeconds}, {"project", projectSeconds},
                          {"rasterize", rasterizeSeconds}, {"composite", compositeSeconds}};
    if (shadingSeconds > 0.0) j["stage_seconds"]["shading"] = shadingSeconds;
    return j;
}

}  // namespace vdbsplat
