// cli/render_flags.cpp — render flags → RenderSettings (see render_flags.h).
#include "cli/render_flags.h"

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

const std::set<std::string>& renderValueFlags() {
    static const std::set<std::string> flags{"--grid",   "--mode",      "--size",      "--tf",    "--eye",
                                             "--look-at", "--up",       "--view-dir",  "--fov",   "--distance",
                                             "--threads", "--spp",      "--threshold", "--lod",   "--footprint",
                                             "--tables",  "--simd", "--max-voxels", "--filter-order", "--subpixels", "--shading",
                                             "--ambient", "--diffuse",  "--specular",  "--shininess",
                                             "--light",   "--gradient-opacity", "--emission", "--emission-map",
                                             "--emission-scale", "--kelvin"};
    return flags;
}

const std::set<std::string>& emissionValueFlags() {
    static const std::set<std::string> flags{"--emission", "--emission-map", "--emission-scale", "--kelvin"};
    return flags;
}

const char* const kEmissionHelp =
    "  --emission GRID    add the emission of scalar grid GRID of the same file (e.g. temperature,\n"
    "                     flame; same transform as the density grid) on the density's kernels\n"
    "  --emission-map M   blackbody (default): value -> Kelvin (--kelvin) -> Planck colour, brightness\n"
    "                     (T^4 - LO^4)/(HI^4 - LO^4); or a transfer function (preset or JSON file) whose\n"
    "                     emission sigma*c is used without its extinction\n"
    "  --emission-scale K emitted radiance per voxel length at the map's brightest value (default 1)\n"
    "  --kelvin LO,HI     blackbody: Kelvin at normalised value 0 and 1 (default 1500,6500)\n";

EmissionSettings emissionFromFlags(const Args& args) {
    EmissionSettings e;
    if (auto v = args.get("--emission")) {
        if (v->empty()) throw Error("--emission: expected a grid name, got ''");
        e.grid = *v;
    }
    for (const char* flag : {"--emission-map", "--emission-scale", "--kelvin"})
        if (args.has(flag) && !e.active()) throw Error(std::string(flag) + ": needs --emission GRID");
    if (auto v = args.get("--emission-map")) e.map = *v;
    if (auto v = args.get("--emission-scale")) e.scale = parseDouble(*v, "--emission-scale");
    if (auto v = args.get("--kelvin")) {
        if (e.map != "blackbody") throw Error("--kelvin: only for --emission-map blackbody");
        const auto k = parseDoubleList(*v, "--kelvin", 2);
        e.kelvinLo = k[0], e.kelvinHi = k[1];
    }
    e.validate();
    return e;
}

const std::set<std::string>& shadingValueFlags() {
    static const std::set<std::string> flags{"--shading",   "--ambient", "--diffuse",         "--specular",
                                             "--shininess", "--light",   "--gradient-opacity"};
    return flags;
}

const char* const kShadingHelp =
    "  --shading S        off (default) | phong | ct: gradient-based Blinn-Phong, computed per voxel\n"
    "                     before rendering (every mode, the reference too); ct: phong with the CT\n"
    "                     preset (ambient 0.25, diffuse 0.75, specular 0.35, shininess 24)\n"
    "  --ambient K        ambient coefficient in [0, 1] (default 0.3; needs --shading)\n"
    "  --diffuse K        diffuse coefficient in [0, 1] (default 0.7; needs --shading)\n"
    "  --specular K       specular coefficient in [0, 1] (default 0.2; needs --shading)\n"
    "  --shininess P      specular exponent in [1, 1000] (default 20; needs --shading)\n"
    "  --light X,Y,Z      directional light, world direction towards the light (default: a\n"
    "                     headlight at the eye; needs --shading)\n"
    "  --gradient-opacity K  scale each voxel's extinction by 1 - exp(-K |grad|), |grad| in\n"
    "                     normalised value per voxel (default 0: off; see docs/shading.md)\n";

ShadingSettings shadingFromFlags(const Args& args) {
    ShadingSettings s;
    if (auto v = args.get("--shading")) {
        if (*v == "ct") s = ShadingSettings::ctPreset();
        else if (*v == "phong") s.mode = ShadingMode::Phong;
        else if (*v != "off") throw Error("--shading: expected 'off', 'phong' or 'ct', got '" + *v + "'");
    }
    for (const char* flag : {"--ambient", "--diffuse", "--specular", "--shininess", "--light"})
        if (args.has(flag) && s.mode == ShadingMode::Off)
            throw Error(std::string(flag) + ": needs --shading phong or ct");
    const auto number = [&](const char* flag, float& to) {
        if (auto v = args.get(flag)) to = float(parseDouble(*v, flag));
    };
    number("--ambient", s.ambient);
    number("--diffuse", s.diffuse);
    number("--specular", s.specular);
    number("--shininess", s.shininess);
    number("--gradient-opacity", s.gradientOpacity);
    if (auto v = args.get("--light")) {
        s.hasLight = true;
        s.light = parseVec3(*v, "--light");
    }
    s.validate();
    return s;
}

glm::dvec3 parseVec3(const std::string& text, const std::string& flag) {
    const auto v = parseDoubleList(text, flag, 3);
    return {v[0], v[1], v[2]};
}

RenderSettings settingsFromFlags(const Args& args) {
    RenderSettings s;
    if (auto v = args.get("--mode")) s.mode = parseRenderMode(*v);
    if (auto v = args.get("--size")) parseSize(*v, "--size", 16384, s.camera.width, s.camera.height);
    if (auto v = args.get("--tf")) s.transferFunction = *v;
    if (auto v = args.get("--grid")) s.gridName = *v;
    if (auto v = args.get("--fov")) s.camera.fovDeg = parseDouble(*v, "--fov");
    if (auto v = args.get("--distance")) s.camera.distance = parseDouble(*v, "--distance");
    if (auto v = args.get("--threads")) s.threads = int(parseInt(*v, "--threads", 0, 1024));
    if (auto v = args.get("--spp")) s.spp = int(parseInt(*v, "--spp", 1, 1024));
    if (auto v = args.get("--threshold")) s.threshold = parseDouble(*v, "--threshold");
    if (auto v = args.get("--max-voxels"))
        s.maxActiveVoxels = uint64_t(parseInt(*v, "--max-voxels", 1, (long long)kHardMaxActiveVoxels));
    if (auto v = args.get("--footprint")) s.footprint = parseFootprintPath(*v);
    applyFilterFlags(args, s);
    if (auto v = args.get("--lod")) s.lodPx = parseDouble(*v, "--lod");
    if (auto v = args.get("--simd")) {
        if (*v != "on" && *v != "off") throw Error("--simd: expected 'on' or 'off', got '" + *v + "'");
        s.simd = *v == "on";
    }
    s.showPrimitives = args.has("--show-primitives");
    s.shading = shadingFromFlags(args);
    s.emission = emissionFromFlags(args);
    if (auto v = args.get("--tables")) {
        if (v->empty()) throw Error("--tables: expected a directory, got ''");
        s.tablesDir = *v;
    }
    if (args.has("--look-at") && !args.has("--eye")) throw Error("--look-at: needs --eye");
    if (args.has("--view-dir") && args.has("--eye")) throw Error("--view-dir: not with --eye (it sets the framing direction)");
    if (auto u = args.get("--up")) s.camera.up = parseVec3(*u, "--up");
    if (auto v = args.get("--view-dir")) {
        s.camera.hasViewDir = true;
        s.camera.viewDir = parseVec3(*v, "--view-dir");
    }
    if (auto v = args.get("--eye")) {
        s.camera.hasEye = true;
        s.camera.eye = parseVec3(*v, "--eye");
    }
    s.validate();
    return s;
}

void applyFilterFlags(const Args& args, RenderSettings& s) {
    if (auto v = args.get("--filter-order")) s.filterOrder = parseFilterOrder(*v);
    if (auto v = args.get("--subpixels")) s.subpixels = int(parseInt(*v, "--subpixels", 1, kMaxSubpixels));
}

void resolveLookAt(const Args& args, const Volume& volume, RenderSettings& settings) {
    if (!args.get("--eye")) return;
    if (auto l = args.get("--look-at")) {
        settings.camera.lookAt = parseVec3(*l, "--look-at");
    } else {
        glm::dvec3 lo, hi;
        volume.worldBounds(lo, hi);
        settings.camera.lookAt = 0.5 * (lo + hi);
    }
}

TransferFunction transferFunctionFor(const RenderSettings& settings) {
    try {
        return TransferFunction::fromSpec(settings.transferFunction);
    } catch (const Error& e) {
        throw Error(std::string("--tf: ") + e.what());
    }
}

}  // namespace vdbsplat::cli
