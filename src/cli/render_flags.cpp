// cli/render_flags.cpp — the render flags: their declarations and → RenderSettings (see render_flags.h).
#include "cli/render_flags.h"

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "footprint/kernel.h"
#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

namespace {

/// One render flag: its name, its value as the help shows it (nullptr: a switch), the help
/// group it is listed under, and its help text (lines of at most 76 characters).
struct RenderFlag {
    const char* name;
    const char* value;
    const char* group;
    const char* help;
};

constexpr const char* kScene = "scene";
constexpr const char* kCamera = "camera";
constexpr const char* kQuality = "rendering";
constexpr const char* kShading = "shading (docs/shading.md)";
constexpr const char* kEmission = "emission (docs/emission.md)";

/// Every render flag, declared once: render, animate, study and bench add them from here.
constexpr RenderFlag kRenderFlags[] = {
    {"--grid", "NAME", kScene, "grid to render (default: the grid named density, else the first\n"
                               "float or double grid)"},
    {"--tf", "PRESET|FILE", kScene, "transfer function: grey (default), ct-bone, fire, or a JSON file"},
    {"--mode", "MODE", kScene,
     "hybrid (default) | splat | point | ewa | swan | none | reference\n"
     "ewa: Zwicker et al. 2001 affine (Jacobian) splats + low-pass; swan: Swan\n"
     "et al. 1997, minified footprints stretched to the pixel filter; none: no\n"
     "low-pass (splats without it, points to the nearest pixel); ewa, swan and\n"
     "none ignore --filter-order/--subpixels (docs/modes.md)"},
    {"--kernel", "K", kScene,
     "reconstruction kernel, every mode and the reference: gaussian (default,\n"
     "s_g 0.65, R 2) | gaussian-sharp (s_g 0.5, R 1.55: less blur when\n"
     "magnified, more ripple; docs/kernel.md)"},
    {"--size", "WxH", kScene, "image size in pixels, each side 1..16384 (default 400x400; study:\n"
                              "200x200)"},
    {"--eye", "X,Y,Z", kCamera, "camera position (world); default: frame the grid from a fixed oblique\n"
                                "view"},
    {"--look-at", "X,Y,Z", kCamera, "point looked at, with --eye (default: the centre of the grid's bounds)"},
    {"--up", "X,Y,Z", kCamera, "up vector (default 0,0,1); animate's zoom and orbit: also the orbit axis"},
    {"--view-dir", "X,Y,Z", kCamera, "without --eye: frame the grid from this direction (centre to eye;\n"
                                     "default 0.9,-1.3,0.75)"},
    {"--fov", "DEG", kCamera, "vertical field of view in (0, 170) degrees (default 30; animate --path:\n"
                              "for keys without fov)"},
    {"--distance", "K", kCamera, "multiplies the framing distance (default 1; 8 far, 1 framed, 0.35\n"
                                 "close); animate --orbit: the orbit's framing distance"},
    {"--threshold", "PX", kQuality, "minification threshold: voxels projecting under PX pixels are points\n"
                                    "(default 1)"},
    {"--lod", "PX[,PX2]", kQuality,
     "level of detail: points are merged into aggregates of 2^3, 4^3 or 8^3\n"
     "voxels (same total optical depth, centroid and spread) whose side\n"
     "projects to at most PX pixels, 0..64 (default 1.25; 0 turns it off).\n"
     "PX2 (>= PX): a larger cap for 4^3 and 8^3 cells in still images; 1.5\n"
     "suits smooth data such as CT (closer to the reference, up to 3x fewer\n"
     "points far away) but blurs sharp-edged opaque content (docs/usage.md)"},
    {"--lod-blend", "auto|on|off|still", kQuality,
     "how blocks pass from one level of detail to the next. on: gradually, so\n"
     "a zoom does not pop; off: at once; still: voxels become 2^3 cells at\n"
     "once, later levels blend (as close or closer, and up to 5.6x faster,\n"
     "for still images).\n"
     "auto (default): on for animate, still otherwise"},
    {"--footprint", "P", kQuality,
     "auto (default): the (i, alpha) reindex table, and the exact ray-centre\n"
     "distance for splats far off the axis where the affine index is off;\n"
     "table: the reindex table for every splat; exact: closed form per pixel"},
    {"--filter-order", "O", kQuality,
     "where the pixel prefilter goes: postfilter (default): composite on a\n"
     "grid with a small low-pass, then low-pass the composited image (right\n"
     "for thin dense structures); prefilter: EWA's order, low-pass each\n"
     "primitive's optical depth, then composite (too opaque for structures\n"
     "1-2 px wide)"},
    {"--subpixels", "K", kQuality,
     "postfilter: composite on K x K sub-pixels per pixel, 1..8, or auto\n"
     "(default: 2 with --shading phong where every voxel is a point, else 1);\n"
     "2 is closer to the reference, at up to 3.5x the time at close views"},
    {"--compositing", "C", kQuality,
     "auto (default): slabs with --shading phong, else kernels; kernels:\n"
     "each splat composited whole at its centre's depth, points summed per\n"
     "one-voxel slab; slabs: every kernel's optical depth spread over the\n"
     "depth slabs it spans along the ray, each slab composited once (closer\n"
     "to the reference where colour changes from voxel to voxel, as shading\n"
     "makes it; ~1.45x the time at framed and close views; docs/compositing.md)"},
    {"--slab-thickness", "V", kQuality,
     "depth slab thickness in voxels, 0.5..1 (default: 1 in the kernels\n"
     "order, 0.5 in the slabs order): points are summed per slab, and the\n"
     "slabs order composites once per slab"},
    {"--cutoff", "T", kQuality,
     "early termination, 1e-6..0.05 (default 1e-3): the deposit that takes a\n"
     "pixel's transmittance below T takes all of it, with its colour, and the\n"
     "pixel takes nothing more; the image moves by at most T (VTK's CPU ray\n"
     "caster stops at 0.0078, the reference at 1e-4; docs/compositing.md)"},
    {"--simd", "on|off", kQuality, "splats through the vector loop (default on) or the scalar table path"},
    {"--show-primitives", nullptr, kQuality, "tint splats red, points keep their colour"},
    {"--tables", "DIR", kQuality,
     "footprint.table and reindex.table from DIR (default: the shipped\n"
     "tables/); a file absent from DIR is built in memory, a corrupt one or\n"
     "one built for another kernel is refused (the forward modes)"},
    {"--spp", "N", kQuality, "reference: rays per pixel, 1..1024 (default 16, rounded up to a square)"},
    {"--max-voxels", "N", kQuality,
     "refuse grids with more than N active voxels, active tiles counted voxel\n"
     "by voxel (default 2^30 = 1073741824, at most 2^32)"},
    {"--threads", "N", kQuality, "worker threads, 0..1024 (default 0: all cores); the image does not\n"
                                 "depend on it"},
    {"--shading", "S", kShading,
     "off (default) | phong | ct: gradient-based Blinn-Phong, computed per\n"
     "voxel before rendering (every mode, the reference too); ct: phong with\n"
     "the CT preset (ambient 0.25, diffuse 0.75, specular 0.35, shininess 24)"},
    {"--ambient", "K", kShading, "ambient coefficient in [0, 1] (default 0.3; needs --shading)"},
    {"--diffuse", "K", kShading, "diffuse coefficient in [0, 1] (default 0.7; needs --shading)"},
    {"--specular", "K", kShading, "specular coefficient in [0, 1] (default 0.2; needs --shading)"},
    {"--shininess", "P", kShading, "specular exponent in [1, 1000] (default 20; needs --shading)"},
    {"--light", "X,Y,Z", kShading, "directional light, world direction towards the light (default: a\n"
                                   "headlight at the eye; needs --shading)"},
    {"--gradient-opacity", "K", kShading,
     "scale each voxel's extinction by 1 - exp(-K |grad|), |grad| in\n"
     "normalised value per voxel, 0..1e6 (default 0: off)"},
    {"--emission", "GRID", kEmission,
     "add the emission of scalar grid GRID of the same file (e.g.\n"
     "temperature, flame; same transform as the density grid) on the\n"
     "density's kernels"},
    {"--emission-map", "M", kEmission,
     "blackbody (default): value -> Kelvin (--kelvin) -> Planck colour,\n"
     "brightness (T^4 - LO^4)/(HI^4 - LO^4); or a transfer function (preset\n"
     "or JSON file) whose emission sigma*c is used without its extinction"},
    {"--emission-scale", "K", kEmission, "emitted radiance per voxel length at the map's brightest value,\n"
                                         "0..1e6 (default 1)"},
    {"--kelvin", "LO,HI", kEmission, "blackbody: Kelvin at normalised value 0 and 1 (default 1500,6500)"},
};

/// @brief --filter-order and --subpixels into @p s. @throw Error naming the flag.
void applyFilterFlags(const Args& args, RenderSettings& s) {
    if (auto v = args.get("--filter-order")) s.filterOrder = parseFilterOrder(*v);
    if (auto v = args.get("--subpixels"))
        s.subpixels = *v == "auto" ? kAutoSubpixels : int(parseInt(*v, "--subpixels", 1, kMaxSubpixels));
}

/// @brief The validated emission settings the emission flags in @p args describe.
/// @throw Error naming the first bad flag (a bad value, or a map flag without --emission).
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

/// @brief The validated shading settings the shading flags in @p args describe.
/// @throw Error naming the first bad flag (a bad value, or a lighting flag without --shading).
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

}  // namespace

void addRenderFlags(CLI::App& app, const std::set<std::string>& leaveOut) {
    for (const RenderFlag& f : kRenderFlags) {
        if (leaveOut.count(f.name)) continue;
        CLI::Option* o = f.value ? addValueFlag(app, f.name, f.value, f.help) : addSwitch(app, f.name, f.help);
        o->group(f.group);
    }
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
    if (auto v = args.get("--cutoff")) s.cutoff = parseDouble(*v, "--cutoff");
    if (auto v = args.get("--max-voxels"))
        s.maxActiveVoxels = uint64_t(parseInt(*v, "--max-voxels", 1, (long long)kHardMaxActiveVoxels));
    if (auto v = args.get("--footprint")) s.footprint = parseFootprintPath(*v);
    if (auto v = args.get("--kernel")) s.kernel = KernelShape::named(*v).id();
    applyFilterFlags(args, s);
    if (auto v = args.get("--lod")) {
        const size_t comma = v->find(',');
        s.lodPx = parseDouble(v->substr(0, comma), "--lod");
        s.lodCoarsePx = comma == std::string::npos ? 0.0 : parseDouble(v->substr(comma + 1), "--lod");  // validate() checks it
    }
    if (auto v = args.get("--lod-blend")) s.lodBlend = parseLodBlend(*v);
    if (auto v = args.get("--compositing")) s.compositing = parseCompositingOrder(*v);
    if (auto v = args.get("--slab-thickness")) s.slabThickness = parseDouble(*v, "--slab-thickness");
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
