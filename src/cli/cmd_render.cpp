// cli/cmd_render.cpp — `vdbsplat render`: its flags (the render flags, -o, --stats, -v), flags →
// RenderSettings → render() → image (+ stats).
// Everything is validated (flags, output path, volume, transfer function, camera)
// before any rendering starts, and outputs are written atomically.
#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/interrupt.h"
#include "cli/render_flags.h"
#include "volume/emission.h"
#include "image/image.h"
#include "render/forward_buffers.h"
#include "render/render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

namespace {

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

void declareRender(CLI::App& app) {
    app.description(
        "render a .vdb grid to PNG or EXR (reference, hybrid, splat, point, ewa, swan, none)\n"
        "\n"
        "usage: vdbsplat render FILE.vdb -o OUT.png|OUT.exr [options]");
    addPositional(app, "FILE.vdb", "the volume to render");
    addValueFlag(app, "-o", "FILE", "output image: .png (8-bit sRGB over black) or .exr (float linear\n"
                                    "RGBA + metadata)")
        ->required();
    addValueFlag(app, "--stats", "FILE.json", "write settings, timings and primitive counts as JSON");
    addValueFlag(app, "--warmup", "N", "render the view N times untimed first, keeping buffers, as bench,\n"
                                       "animate and an interactive viewer do; --stats and -v then time\n"
                                       "the last render alone (0..100, default 0: a cold, one-shot render)");
    addSwitch(app, "-v", "show progress on stderr (a bar with ETA on a terminal, a line per\n"
                         "10% otherwise) and print the statistics in one line at the end");
    addRenderFlags(app);
    app.footer(
        "Ctrl-C or SIGTERM stops the render within a window (forward modes) or a row of rays\n"
        "(reference): nothing is written, exit 1. A second one stops at once.");
}

namespace {
constexpr int kMaxRenderWarmup = 100;
}  // namespace

int runRender(const Args& args) {
    const std::string input = args.onePositional("input .vdb file");
    const std::string output = args.require("-o");
    RenderSettings settings = settingsFromFlags(args);
    checkImagePath(output);
    checkNotAnInput(output, input, "-o");
    const int warmup = args.has("--warmup") ? int(parseInt(*args.get("--warmup"), "--warmup", 0, kMaxRenderWarmup)) : 0;
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
    settings = resolvedFor(volume, camera, settings);    // --subpixels auto: the k used, echoed below

    RenderStats stats;
    RenderControl control;
    control.stop = [&guard] { return guard.interrupted(); };
    std::unique_ptr<ProgressMeter> meter;
    if (args.has("-v")) {
        meter = std::make_unique<ProgressMeter>(toString(settings.mode));
        control.progress = [&meter](double f) { meter->update(f); };
    }
    WindowedImage image;  // the forward modes' data window (render/render.h): a PNG is written from it
    // Kept between the warm-up renders and the timed one, and in every case freed only after the
    // image is written: a render that frees its own buffers pays for the unmapping inside its
    // time (2–10 ms of a one-shot render here; docs/performance.md, session 29). A single render
    // keeps no level-of-detail moments (it would only fill them).
    ForwardBuffers buffers;
    buffers.keepMoments = warmup > 0;
    control.buffers = &buffers;
    try {
        RenderControl quiet = control;  // no progress for the untimed renders
        quiet.progress = nullptr;
        for (int i = 0; i < warmup; ++i) {
            RenderStats untimed;
            buffers.recycle(renderWindowed(volume, tf, settings, untimed, quiet));  // its memory for the next
        }
        image = renderWindowed(volume, tf, settings, stats, control);
    } catch (const RenderStopped&) {
        throw Error("render interrupted by " + guard.signalName() + "; " + output + " not written");
    }
    if (meter) meter->finish();

    nlohmann::json meta = settings.toJson();
    meta.update(stats.toJson());
    meta["width"] = camera.width();
    meta["height"] = camera.height();
    meta["input"] = input;
    meta["warmup"] = warmup;
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
