// cli/cmd_render.cpp — `vdbsplat render`: flags → RenderSettings → render() → image (+ stats).
// Everything is validated (flags, output path, volume, transfer function, camera)
// before any rendering starts, and outputs are written atomically.
#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/interrupt.h"
#include "cli/render_flags.h"
#include "volume/emission.h"
#include "image/image.h"
#include "render/render.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vdbsplat::cli {

namespace {

const char* kHelp =
    "usage: vdbsplat render FILE.vdb -o OUT.png|OUT.exr [options]\n"
    "\n"
    "  -o FILE            output image: .png (8-bit sRGB over black) or .exr (float linear RGBA + metadata)\n"
    VDBSPLAT_SCENE_FLAGS_HELP
    "  --eye X,Y,Z        camera position (world); default: frame the grid from a fixed oblique view\n"
    "  --look-at X,Y,Z    point looked at (default: the centre of the grid's bounds)\n"
    "  --up X,Y,Z         up vector (default 0,0,1)\n"
    "  --view-dir X,Y,Z   without --eye: frame the grid from this direction (centre to eye;\n"
    "                     default 0.9,-1.3,0.75)\n"
    "  --fov DEG          vertical field of view (default 30)\n"
    "  --distance K       multiplies the framing distance (8 far, 1 framed, 0.35 close)\n"
    "  --threshold PX     minification threshold: voxels projecting under PX pixels are points (default 1)\n"
    "  --lod PX           level of detail: points are merged into aggregates of 2^3, 4^3 or 8^3 voxels\n"
    "                     (same total optical depth, centroid and spread) whose side projects to at\n"
    "                     most PX pixels (default 1.25; 0 turns it off)\n"
    "  --simd on|off      splats through the vector loop (default on) or the scalar table path\n"
    "  --footprint P      auto (default): the (i, alpha) reindex table, and the exact ray-centre\n"
    "                     distance for splats far off the axis where the affine index is off;\n"
    "                     table: the reindex table for every splat; exact: closed form per pixel\n"
    "  --filter-order O   where the pixel prefilter goes: postfilter (default): composite on a\n"
    "                     grid with a small low-pass, then low-pass the composited image (right for\n"
    "                     thin dense structures); prefilter: EWA's order, low-pass each primitive's\n"
    "                     optical depth, then composite (too opaque for structures 1-2 px wide)\n"
    "  --subpixels K      postfilter: composite on K x K sub-pixels per pixel, 1..8 (default 1;\n"
    "                     2 is closer to the reference, at up to 3.5x the time at close views)\n"
    "  --show-primitives  tint splats red, points keep their colour\n"
    "  --tables DIR       footprint.table and reindex.table from DIR (default: the shipped tables/);\n"
    "                     a file absent from DIR is built in memory, a corrupt one or one built for\n"
    "                     another kernel is refused (the forward modes)\n"
    "  --spp N            reference: rays per pixel (default 16, rounded up to a square)\n"
    "  --max-voxels N     refuse grids with more than N active voxels, active tiles counted voxel\n"
    "                     by voxel (default 2^30 = 1073741824, at most 2^32)\n"
    "  --threads N        worker threads (default: all cores); the image does not depend on it\n"
    "  --stats FILE.json  write settings, timings and primitive counts as JSON\n"
    "  -v                 show progress on stderr (a bar with ETA on a terminal, a line per\n"
    "                     10% otherwise) and print the statistics in one line at the end\n"
    "\n"
    "Ctrl-C or SIGTERM stops the render within a window (forward modes) or a row of rays\n"
    "(reference): nothing is written, exit 1. A second one stops at once.\n";

/// The stats file is written after the image: check its folder first, so a bad --stats
/// path fails before any work and never leaves an image behind.
void checkStatsPath(const std::string& path, const std::string& image) {
    namespace fs = std::filesystem;
    if (path.empty()) throw Error("--stats: expected a file name, got ''");
    std::error_code ec;
    const fs::path folder = fs::path(path).parent_path();
    if (!folder.empty() && !fs::is_directory(folder, ec)) throw Error("--stats: " + path + ": folder does not exist");
    if (fs::is_directory(path, ec)) throw Error("--stats: " + path + ": is a directory");
    checkOutputPath(path);  // a dangling link or link loop fails before the render
    std::error_code ec1, ec2;
    const fs::path a = fs::weakly_canonical(path, ec1), b = fs::weakly_canonical(image, ec2);
    if (!ec1 && !ec2 && a == b) throw Error("--stats: " + path + ": is the output image (-o)");
}

std::string oneLine(const RenderStats& st, const RenderSettings& s) {
    char buf[512];
    const uint64_t drawn = st.points + st.splats;
    std::snprintf(buf, sizeof buf,
                  "%s %dx%d: %.3f s, %llu active voxels, %llu points, %llu splats (%.1f%%), %llu culled; "
                  "stream %.3f project %.3f rasterize %.3f composite %.3f s",
                  toString(s.mode).c_str(), s.camera.width, s.camera.height, st.seconds,
                  (unsigned long long)st.activeVoxels, (unsigned long long)st.points, (unsigned long long)st.splats,
                  drawn ? 100.0 * st.splats / drawn : 0.0, (unsigned long long)st.culled, st.streamSeconds,
                  st.projectSeconds, st.rasterizeSeconds, st.compositeSeconds);
    return buf;
}

}  // namespace

int runRender(const Argv& argv) {
    std::set<std::string> valueFlags = renderValueFlags();
    valueFlags.insert({"-o", "--stats"});
    const Args args(argv, valueFlags, {"-v", "--show-primitives"});
    if (args.wantsHelp()) {
        std::cout << kHelp << "\nshading (docs/shading.md):\n" << kShadingHelp << "\nemission (docs/emission.md):\n"
                  << kEmissionHelp;
        return 0;
    }
    const std::string input = args.onePositional("input .vdb file");
    const std::string output = args.require("-o");
    RenderSettings settings = settingsFromFlags(args);
    checkImagePath(output);
    checkNotAnInput(output, input, "-o");
    const auto statsPath = args.get("--stats");
    if (statsPath) checkStatsPath(*statsPath, output), checkNotAnInput(*statsPath, input, "--stats");

    InterruptGuard guard;  // before loading: a Ctrl-C then stops the render before it starts
    std::unique_ptr<tbb::global_control> threads;
    if (settings.threads > 0)
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, settings.threads);

    const TransferFunction tf = transferFunctionFor(settings);
    const Volume volume = loadVolumeWithEmission(input, settings.gridName, settings.emission.grid);
    checkVoxelBudget(volume, settings);
    resolveLookAt(args, volume, settings);
    const Camera camera = cameraFor(volume, settings);  // validates eye/look-at/up before the work

    RenderStats stats;
    RenderControl control;
    control.stop = [&guard] { return guard.interrupted(); };
    std::unique_ptr<ProgressMeter> meter;
    if (args.has("-v")) {
        meter = std::make_unique<ProgressMeter>(toString(settings.mode));
        control.progress = [&meter](double f) { meter->update(f); };
    }
    Image image;
    try {
        image = render(volume, tf, settings, stats, control);
    } catch (const RenderStopped&) {
        throw Error("render interrupted by " + guard.signalName() + "; " + output + " not written");
    }
    if (meter) meter->finish();

    nlohmann::json meta = settings.toJson();
    meta.update(stats.toJson());
    meta["width"] = camera.width();
    meta["height"] = camera.height();
    meta["input"] = input;
    meta["grid"] = volume.name;
    meta["camera"] = camera.describe();
    meta["transfer_function"] = nlohmann::json::parse(tf.toJson());
    if (volume.nonFiniteCount) meta["non_finite_voxels_zeroed"] = volume.nonFiniteCount;
    writeImage(output, image,
               {{"settings", settings.toJson().dump()},
                {"camera", camera.describe()},
                {"mode", toString(settings.mode)},
                {"transfer_function", tf.toJson()},
                {"seconds", std::to_string(stats.seconds)}});
    if (statsPath) writeTextFileAtomic(*statsPath, meta.dump(2) + "\n");
    if (args.has("-v")) std::cout << oneLine(stats, settings) << "\n";
    if (volume.nonFiniteCount)
        std::cerr << "vdbsplat: warning: " << input << ": " << volume.nonFiniteCount
                  << " active voxels with NaN or infinite values were treated as zero\n";
    return 0;
}

}  // namespace vdbsplat::cli
