// cli/cmd_animate.cpp — `vdbsplat animate`: load the grid once, render a camera path to frames.
// Owns: the animate flags (declared here; the render flags through render_flags.h), the output folder
// protocol (refuse a non-empty folder without --resume/--force; animation.json and
// reference/reference.json record what the frames were made with, so --resume never mixes
// two animations), the frame loop (render() per frame, atomic frames, frames.csv kept
// consistent while running: rewritten at most once a second and at the end or on an
// interruption), the Ctrl-C/SIGTERM flag checked between frames, the progress bar, the plot
// and the optional MP4. The path maths, flicker, CSV rows and plot are in animation/.
#include <CLI/App.hpp>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "animation/camera_path.h"
#include "animation/folder_record.h"
#include "animation/frame_stats.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/interrupt.h"
#include "cli/render_flags.h"
#include "volume/emission.h"
#include "image/image.h"
#include "metrics/metrics.h"
#include "render/forward_buffers.h"
#include "render/render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"

extern char** environ;

namespace vdbsplat::cli {

namespace {

namespace fs = std::filesystem;
using animation::FrameRecord;

// ---- the path -----------------------------------------------------------------------------

struct Frame {
    CameraSpec camera;  ///< the spec render() gets (size, fov and the eye or the framing distance)
    double time = 0.0;
    double distance = std::numeric_limits<double>::quiet_NaN();
};

struct Options {
    std::string input, dir;
    RenderSettings settings;
    std::string format = "png";
    bool resume = false, force = false, reference = false, mp4 = false;
    double fps = 24.0;
    bool fpsGiven = false;
    // path
    enum class Kind { Zoom, Orbit, Keys } kind = Kind::Zoom;
    double from = 0, to = 0, orbitDeg = 0;
    std::optional<long long> frames;
    std::vector<animation::CameraKey> keys;
    std::string pathFile;
};

Options optionsFrom(const Args& args) {
    Options o;
    o.input = args.onePositional("input .vdb file");
    o.dir = args.require("-o");
    if (o.dir.empty()) throw Error("-o: expected a folder, got ''");
    o.settings = settingsFromFlags(args);
    if (auto v = args.get("--format")) {
        if (*v != "png" && *v != "exr") throw Error("--format: expected 'png' or 'exr', got '" + *v + "'");
        o.format = *v;
    }
    o.resume = args.has("--resume");
    o.force = args.has("--force");
    if (o.resume && o.force) throw Error("--resume: not with --force (choose one)");
    o.reference = args.has("--reference");
    o.mp4 = args.has("--mp4");
    if (auto v = args.get("--frames")) o.frames = parseInt(*v, "--frames", 1, animation::kMaxFrames);
    if (auto v = args.get("--fps")) {
        o.fps = parseDouble(*v, "--fps");
        if (!(o.fps > 0.0 && o.fps <= 1000.0)) throw Error("--fps: must be a number in (0, 1000]");
        o.fpsGiven = true;
    }
    const bool zoom = args.has("--from") || args.has("--to"), orbit = args.has("--orbit"), keys = args.has("--path");
    if (int(zoom) + int(orbit) + int(keys) != 1)
        throw Error(std::string(zoom + orbit + keys == 0 ? "no camera path" : "more than one camera path") +
                    ": give --from/--to, --orbit or --path (see --help)");
    if (zoom) {
        o.kind = Options::Kind::Zoom;
        o.from = parseDouble(args.require("--from"), "--from");
        o.to = parseDouble(args.require("--to"), "--to");
        if (!(o.from > 0.0 && o.from < 1e6)) throw Error("--from: must be a positive number below 1e6");
        if (!(o.to > 0.0 && o.to < 1e6)) throw Error("--to: must be a positive number below 1e6");
        if (args.has("--distance")) throw Error("--distance: not with --from/--to (the zoom sets the distance)");
        if (!o.frames) throw Error("--frames: required with --from/--to");
    } else if (orbit) {
        o.kind = Options::Kind::Orbit;
        o.orbitDeg = parseDouble(*args.get("--orbit"), "--orbit");
        if (std::abs(o.orbitDeg) > 36000.0) throw Error("--orbit: at most 36000 degrees");
        if (!o.frames) throw Error("--frames: required with --orbit");
    } else {
        o.kind = Options::Kind::Keys;
        o.pathFile = *args.get("--path");
        if (args.has("--distance")) throw Error("--distance: not with --path (the keyframes place the camera)");
        if (args.has("--view-dir")) throw Error("--view-dir: not with --path (the keyframes place the camera)");
        if (o.frames && o.fpsGiven) throw Error("--frames: not with --fps for --path (choose one)");
        if (!o.frames && !o.fpsGiven) throw Error("--frames: --path needs --frames N or --fps F");
        if (o.pathFile.empty()) throw Error("--path: expected a file name, got ''");
        o.keys = animation::loadKeyframes(o.pathFile, o.settings.camera.up, o.settings.camera.fovDeg);
    }
    return o;
}

std::vector<Frame> framesFor(const Options& o, const Volume& volume) {
    std::vector<Frame> frames;
    CameraSpec base = o.settings.camera;
    switch (o.kind) {
        case Options::Kind::Zoom: {
            const auto d = animation::zoomDistances(o.from, o.to, *o.frames);
            for (size_t i = 0; i < d.size(); ++i) {
                Frame f;
                f.camera = base;
                f.camera.distance = d[i];
                f.time = double(i);
                f.distance = d[i];
                frames.push_back(f);
            }
            break;
        }
        case Options::Kind::Orbit: {
            RenderSettings s = o.settings;
            const Camera start = cameraFor(volume, s);
            const auto eyes = animation::orbitEyes(start.lookAt(), start.eye(), base.up, o.orbitDeg, *o.frames);
            for (size_t i = 0; i < eyes.size(); ++i) {
                Frame f;
                f.camera = base;
                f.camera.hasEye = true;
                f.camera.hasViewDir = false;
                f.camera.eye = eyes[i];
                f.camera.lookAt = start.lookAt();
                f.time = double(i);
                f.distance = base.distance;
                frames.push_back(f);
            }
            break;
        }
        case Options::Kind::Keys: {
            const auto times = o.frames ? animation::uniformTimes(o.keys, *o.frames) : animation::timesAtRate(o.keys, o.fps);
            for (const double t : times) {
                const auto c = animation::interpolate(o.keys, t);
                Frame f;
                f.camera = base;
                f.camera.hasEye = true;
                f.camera.eye = c.eye;
                f.camera.lookAt = c.lookAt;
                f.camera.up = c.up;
                f.camera.fovDeg = c.fovDeg;
                f.time = t;
                frames.push_back(f);
            }
            break;
        }
    }
    return frames;
}

// ---- the folder ---------------------------------------------------------------------------

bool nonEmptyFolder(const fs::path& dir) {
    std::error_code ec;
    return fs::is_directory(dir, ec) && fs::directory_iterator(dir, ec) != fs::directory_iterator();
}

/// Our own file names only: frame_NNNN.(png|exr) and the writers' temporaries of them.
bool isFrameFile(const std::string& name) {
    static const std::regex re(R"(frame_[0-9]{4,6}\.(png|exr)(\.tmp[0-9]+\.(png|exr))?)");
    return std::regex_match(name, re);
}
bool isFrameTemporary(const std::string& name) {
    static const std::regex re(R"(frame_[0-9]{4,6}\.(png|exr)\.tmp[0-9]+\.(png|exr))");
    return std::regex_match(name, re);
}

void removeMatching(const fs::path& dir, bool (*match)(const std::string&)) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return;
    std::vector<fs::path> doomed;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.is_regular_file(ec) && match(e.path().filename().string())) doomed.push_back(e.path());
    for (const auto& p : doomed) fs::remove(p, ec);
}



std::optional<nlohmann::json> readJson(const fs::path& p) {
    std::error_code ec;
    if (!fs::exists(p, ec)) return std::nullopt;
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    try {
        return nlohmann::json::parse(s.str());
    } catch (const nlohmann::json::exception&) {
        throw Error(p.string() + ": cannot be read (a damaged animation record; use --force to start afresh)");
    }
}

/// Reads back DIR/frames.csv's rows (only when its header is the expected one).
std::vector<std::optional<FrameRecord>> readRows(const fs::path& csv, bool reference, size_t frames) {
    std::vector<std::optional<FrameRecord>> rows(frames);
    std::ifstream in(csv);
    std::string line;
    if (!in || !std::getline(in, line) || line != animation::csvHeader(reference)) return rows;
    while (std::getline(in, line)) {
        const auto r = animation::parseCsvRow(line, reference);
        if (r && r->frame >= 0 && size_t(r->frame) < frames) rows[size_t(r->frame)] = r;
    }
    return rows;
}

std::optional<Image> readValid(const fs::path& p, const CameraSpec& spec) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) return std::nullopt;
    try {
        Image im = readImage(p.string());
        if (im.width != spec.width || im.height != spec.height) return std::nullopt;
        return im;
    } catch (const Error&) {
        return std::nullopt;
    }
}

std::string frameName(size_t i, size_t count, const std::string& ext) {
    const int digits = std::max<int>(4, int(std::to_string(count > 0 ? count - 1 : 0).size()));
    char buf[64];
    std::snprintf(buf, sizeof buf, "frame_%0*zu.%s", digits, i, ext.c_str());
    return buf;
}

void progress(size_t done, size_t total, double elapsed, size_t rendered) {
    const int width = 30;
    const int filled = total ? int(double(width) * double(done) / double(total)) : width;
    std::string bar(size_t(filled), '#');
    bar.resize(width, ' ');
    std::string eta = "ETA --";
    if (rendered > 0 && done < total) eta = "ETA " + durationText(elapsed / double(rendered) * double(total - done));
    else if (done >= total) eta = "done in " + durationText(elapsed);
    std::fprintf(stderr, "\r[%s] %zu/%zu frames  %s   ", bar.c_str(), done, total, eta.c_str());
    std::fflush(stderr);
}

std::optional<std::string> findOnPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (!path) return std::nullopt;
    std::stringstream s(path);
    std::string dir;
    while (std::getline(s, dir, ':')) {
        if (dir.empty()) continue;
        const fs::path p = fs::path(dir) / program;
        if (::access(p.c_str(), X_OK) == 0 && fs::is_regular_file(p)) return p.string();
    }
    return std::nullopt;
}

/// Runs ffmpeg over the frames into DIR/animation.mp4 (temporary + rename).
void encodeMp4(const std::string& ffmpeg, const fs::path& dir, size_t count, const std::string& ext, double fps) {
    const int digits = std::max<int>(4, int(std::to_string(count > 0 ? count - 1 : 0).size()));
    const std::string pattern = (dir / ("frame_%0" + std::to_string(digits) + "d." + ext)).string();
    const fs::path out = dir / "animation.mp4", tmp = dir / ("animation.tmp" + std::to_string(::getpid()) + ".mp4");
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", fps);
    std::vector<std::string> argv{ffmpeg, "-nostdin", "-y", "-loglevel", "error", "-framerate", rate, "-i", pattern,
                                  "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", tmp.string()};
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, cargv.data(), environ) != 0)
        throw Error("--mp4: cannot start " + ffmpeg);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    std::error_code ec;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fs::remove(tmp, ec);
        throw Error("--mp4: ffmpeg failed on " + pattern + " (the frames are kept)");
    }
    fs::rename(tmp, out, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error("--mp4: cannot move the video into place: " + out.string());
    }
}

}  // namespace

void declareAnimate(CLI::App& app) {
    app.description(
        "render a camera path (zoom, orbit, keyframes) to frames, with per-frame stats\n"
        "\n"
        "usage: vdbsplat animate FILE.vdb -o DIR (--from K --to K | --orbit DEG | --path FILE.json) [options]\n"
        "\n"
        "Loads the grid once and renders a camera path into DIR as frame_0000.png, frame_0001.png, …\n"
        "(each written atomically), with per-frame statistics in DIR/frames.csv.");
    addPositional(app, "FILE.vdb", "the volume to render");
    const std::string path = "path (exactly one of zoom, orbit, keyframes)", output = "output";
    addValueFlag(app, "--from", "K", "zoom: framing distance of the first frame (as --distance: 8 far, 1\n"
                                     "framed, 0.125 close); with --to")
        ->group(path);
    addValueFlag(app, "--to", "K", "zoom: framing distance of the last frame; the distances between are\n"
                                   "spaced geometrically (the same zoom factor between any two frames)")
        ->group(path);
    addValueFlag(app, "--orbit", "DEG", "orbit: the eye at --distance turns DEG degrees about the up axis\n"
                                        "through the centre of the grid's bounds; frame i at DEG*i/N (so 360\n"
                                        "loops seamlessly)")
        ->group(path);
    addValueFlag(app, "--path", "FILE.json", "keyframes: [{\"eye\": [x,y,z], \"look_at\": [x,y,z], \"up\": [x,y,z],\n"
                                             "\"fov\": DEG, \"time\": S}, …] (up and fov optional: --up, --fov),\n"
                                             "times increasing; Catmull-Rom spline on eye, look-at and up,\n"
                                             "monotone cubic on fov")
        ->group(path);
    addValueFlag(app, "--frames", "N", "frames, 1..100000 (required for zoom and orbit; --path: or --fps)")->group(path);
    addValueFlag(app, "--fps", "F", "--path without --frames: sample the keyframes at F frames per second;\n"
                                    "also the MP4's frame rate (default 24)")
        ->group(path);
    addValueFlag(app, "-o", "DIR", "output folder (created; its parent must exist). A non-empty DIR is\n"
                                   "refused unless --resume or --force is given")
        ->required()
        ->group(output);
    addValueFlag(app, "--format", "F", "png (default; 8-bit sRGB over black) | exr (float linear RGBA)")->group(output);
    addSwitch(app, "--resume", "keep frames already in DIR (readable, the right size, with their row in\n"
                               "frames.csv) and render the rest; refused if DIR was made with other\n"
                               "settings")
        ->group(output);
    addSwitch(app, "--force", "start afresh in a non-empty DIR (removes its frames, frames.csv,\n"
                              "plot.svg, animation.json, animation.mp4 and reference/)")
        ->group(output);
    addSwitch(app, "--reference", "also render reference frames (mode reference, --spp; cached as EXR in\n"
                                  "DIR/reference/, reused by --resume) and add to frames.csv the PSNR of\n"
                                  "each frame and its flicker F_t = mean |(I_t - I_t-1) - (R_t - R_t-1)|\n"
                                  "over pixels and RGB of display values; writes DIR/plot.svg (PSNR,\n"
                                  "flicker, splat fraction, and the frames where the splat fraction\n"
                                  "crosses 50% or steps by > 10 points)")
        ->group(output);
    addSwitch(app, "--mp4", "also encode DIR/animation.mp4 with ffmpeg when it is on PATH (else a\n"
                            "note)")
        ->group(output);
    addRenderFlags(app, {"--eye", "--look-at"});  // the path places the camera
    app.footer(
        "Ctrl-C or SIGTERM stops after the frame being rendered (a second one stops at once):\n"
        "finished frames and frames.csv stay consistent, exit 1. Prints a summary line on stdout.");
}

int runAnimate(const Args& args) {
    Options o = optionsFrom(args);
    const fs::path dir(o.dir);
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw Error("-o: " + o.dir + ": exists and is not a folder");
    if (!fs::exists(dir, ec)) {
        const fs::path parent = fs::absolute(dir, ec).parent_path();
        if (!fs::is_directory(parent, ec)) throw Error("-o: " + o.dir + ": parent folder does not exist");
    }
    if (nonEmptyFolder(dir) && !o.resume && !o.force)
        throw Error("-o: " + o.dir + ": folder is not empty (use --resume to continue it or --force to start afresh)");

    std::unique_ptr<tbb::global_control> threads;
    if (o.settings.threads > 0)
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.settings.threads);
    const TransferFunction tf = transferFunctionFor(o.settings);
    const Volume volume = loadVolumeWithEmission(o.input, o.settings.gridName, o.settings.emission.grid);
    const std::vector<Frame> frames = framesFor(o, volume);
    const size_t M = frames.size();

    // Every camera is built (and so validated) before anything is written.
    std::string cameraText;
    std::vector<Camera> cameras;
    cameras.reserve(M);
    for (size_t i = 0; i < M; ++i) {
        RenderSettings s = o.settings;
        s.camera = frames[i].camera;
        try {
            cameras.push_back(cameraFor(volume, s));
        } catch (const Error& e) {
            const std::string where = o.kind == Options::Kind::Keys ? o.pathFile + ": frame " : "frame ";
            throw Error(where + std::to_string(i) + " (time " + std::to_string(frames[i].time) + "): " + e.what());
        }
        cameraText += cameras.back().describe() + "\n";
    }

    // --subpixels auto is fixed for the whole path, so that a zoom never switches grids between
    // two frames: 2 only where it would be 2 at every frame (render.h resolvedFor).
    if (o.settings.subpixels == kAutoSubpixels) {
        const bool everyFrameMinified = std::all_of(cameras.begin(), cameras.end(), [&](const Camera& c) {
            return everyVoxelMinified(volume, c, o.settings.threshold);
        });
        o.settings.subpixels = o.settings.effectiveSubpixels(everyFrameMinified);
    }
    // --lod-blend auto: frames of a path blend every level-of-detail passage, so that no block
    // pops between two frames (a still image switches the first passage: RenderSettings).
    if (!o.settings.lodBlend) o.settings.lodBlend = LodBlend::On;

    // What the frames are made of: --resume refuses a folder made otherwise.
    std::error_code canonicalEc;
    const std::string inputId = fs::weakly_canonical(o.input, canonicalEc).string();
    nlohmann::json settingsJson = o.settings.identityJson();
    settingsJson.erase("distance");
    nlohmann::json record = {{"input", inputId},       {"grid", volume.name}, {"settings", settingsJson},
                             {"format", o.format},     {"frames", M},         {"cameras_fnv1a", animation::cameraFingerprint(cameraText)},
                             {"reference", o.reference}};
    nlohmann::json refRecord = {{"input", inputId},     {"grid", volume.name},
                                {"tf", o.settings.transferFunction}, {"spp", o.settings.spp},
                                {"width", o.settings.camera.width},  {"height", o.settings.camera.height},
                                {"frames", M},          {"cameras_fnv1a", animation::cameraFingerprint(cameraText)}};
    const fs::path refDir = dir / "reference";
    if (o.resume) {
        if (auto old = readJson(dir / "animation.json"); old && !animation::sameAnimation(*old, record, cameraText)) {
            if (animation::olderBuildsRecord(*old, record, cameraText))
                throw Error(o.dir + ": --resume: the folder was made by an older vdbsplat, whose record leaves out "
                            "settings at their defaults (--cutoff's was 1e-4 until 2026-11-29, today's is 1e-3): new "
                            "frames might not match its frames (use --force to start afresh)");
            throw Error(o.dir + ": --resume: the folder holds another animation (input, settings, path or "
                        "--reference differ; use --force to start afresh)");
        }
        if (o.reference)
            if (auto old = readJson(refDir / "reference.json"); old && !animation::sameAnimation(*old, refRecord, cameraText))
                throw Error((refDir / "reference.json").string() +
                            ": --resume: reference frames of another animation (use --force to start afresh)");
    }

    // The work starts: create or clean the folder.
    fs::create_directory(dir, ec);
    if (!fs::is_directory(dir)) throw Error("-o: " + o.dir + ": cannot create folder: " + ec.message());
    if (o.force) {
        removeMatching(dir, isFrameFile);
        for (const char* name : {"frames.csv", "plot.svg", "animation.json", "animation.mp4"}) fs::remove(dir / name, ec);
        removeMatching(refDir, isFrameFile);
        fs::remove(refDir / "reference.json", ec);
        fs::remove(refDir, ec);  // only when empty
    } else {
        removeMatching(dir, isFrameTemporary);  // left by a process killed while writing
        removeMatching(refDir, isFrameTemporary);
    }
    writeTextFileAtomic((dir / "animation.json").string(), record.dump(2) + "\n");
    if (o.reference) {
        fs::create_directory(refDir, ec);
        if (!fs::is_directory(refDir)) throw Error(refDir.string() + ": cannot create folder: " + ec.message());
        writeTextFileAtomic((refDir / "reference.json").string(), refRecord.dump(2) + "\n");
    }

    const fs::path csvPath = dir / "frames.csv";
    std::vector<std::optional<FrameRecord>> rows =
        o.resume ? readRows(csvPath, o.reference, M) : std::vector<std::optional<FrameRecord>>(M);
    auto writeCsv = [&] {
        std::vector<FrameRecord> present;
        for (const auto& r : rows)
            if (r) present.push_back(*r);
        animation::markSwitches(present);  // neighbours in the file
        std::string text = animation::csvHeader(o.reference) + "\n";
        for (const auto& r : present) text += animation::csvRow(r, o.reference) + "\n";
        writeTextFileAtomic(csvPath.string(), text);
        return present;
    };

    const bool tty = ::isatty(2) == 1;
    InterruptGuard guard;
    ForwardBuffers buffers;  // kept from frame to frame (render/forward_buffers.h)
    RenderControl control;
    control.buffers = &buffers;
    const auto start = std::chrono::steady_clock::now();
    auto lastCsv = start;
    size_t done = 0, rendered = 0, skipped = 0;
    std::optional<Image> previous, referencePrevious;
    if (tty) progress(0, M, 0.0, 0);
    for (size_t i = 0; i < M && !guard.interrupted(); ++i) {
        RenderSettings s = o.settings;
        s.camera = frames[i].camera;
        const fs::path framePath = dir / frameName(i, M, o.format);
        std::optional<Image> image;
        if (rows[i]) {
            image = readValid(framePath, s.camera);
            if (!image) rows[i].reset();
        }
        std::optional<Image> referenceImage;
        std::optional<double> referenceSeconds;
        if (o.reference) {
            const fs::path refPath = refDir / frameName(i, M, "exr");
            referenceImage = readValid(refPath, s.camera);
            if (!referenceImage) {
                RenderSettings r = s;
                r.mode = RenderMode::Reference;
                RenderStats rs;
                Image im = render(volume, tf, r, rs, control);
                writeImage(refPath.string(), im,
                           {{"settings", r.toJson().dump()}, {"camera", cameras[i].describe()}, {"mode", "reference"}});
                referenceImage = std::move(im);
                referenceSeconds = rs.seconds;
                if (guard.interrupted() && !rows[i]) break;
            }
        }
        if (rows[i]) {
            ++skipped;
        } else {
            RenderStats st;
            WindowedImage im = renderWindowed(volume, tf, s, st, control);  // timed as `vdbsplat render` times it
            writeImage(framePath.string(), im,
                       {{"settings", s.toJson().dump()},
                        {"camera", cameras[i].describe()},
                        {"mode", toString(s.mode)},
                        {"transfer_function", tf.toJson()},
                        {"seconds", std::to_string(st.seconds)}});
            image = o.format == "png" ? readImage(framePath.string()) : im.full();  // metrics of the frame as written
            buffers.recycle(std::move(im));  // its memory for the next frame
            FrameRecord r;
            r.frame = (long long)i;
            r.time = frames[i].time;
            r.distance = frames[i].distance;
            const glm::dvec3 eye = cameras[i].eye();
            for (int k = 0; k < 3; ++k) r.eye[k] = eye[k];
            r.fov = cameras[i].fovDeg();
            r.seconds = st.seconds;
            r.points = st.points;
            r.splats = st.splats;
            r.splatFraction = st.points + st.splats ? double(st.splats) / double(st.points + st.splats) : 0.0;
            if (o.reference) {
                r.psnr = compareImages(*image, *referenceImage).psnr;
                if (previous && referencePrevious)
                    r.flicker = animation::flicker(*image, *previous, *referenceImage, *referencePrevious);
                r.referenceSeconds = referenceSeconds.value_or(0.0);
            }
            rows[i] = r;
            ++rendered;
        }
        ++done;
        if (o.reference) {
            previous = std::move(image);
            referencePrevious = std::move(referenceImage);
        }
        const auto now = std::chrono::steady_clock::now();
        if (std::chrono::duration<double>(now - lastCsv).count() >= 1.0) {
            writeCsv();
            lastCsv = now;
        }
        if (tty) progress(done, M, std::chrono::duration<double>(now - start).count(), rendered);
    }
    const std::vector<FrameRecord> present = writeCsv();
    if (tty) std::fprintf(stderr, "\n");
    if (guard.interrupted())
        throw Error("interrupted after " + std::to_string(done) + " of " + std::to_string(M) + " frames");

    // Summary (and the plot with --reference).
    double sumFlicker = 0.0, minPsnr = std::numeric_limits<double>::infinity(), worstDrop = 0.0;
    size_t nFlicker = 0, crossings = 0, steps = 0;
    for (size_t i = 0; i < present.size(); ++i) {
        const FrameRecord& r = present[i];
        if (r.marker == "cross") ++crossings;
        if (r.marker == "step") ++steps;
        if (r.flicker) sumFlicker += *r.flicker, ++nFlicker;
        if (r.psnr) minPsnr = std::min(minPsnr, *r.psnr);
        if (r.psnr && i > 0 && present[i - 1].psnr && std::isfinite(*r.psnr) && std::isfinite(*present[i - 1].psnr))
            worstDrop = std::max(worstDrop, std::abs(*r.psnr - *present[i - 1].psnr));
    }
    std::ostringstream summary;
    summary.precision(4);
    summary << M << " frames (" << rendered << " rendered, " << skipped << " kept) in "
            << durationText(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count())
            << "; splat-fraction switches: " << crossings << " crossing 50%, " << steps << " steps > 10 points";
    if (o.reference) {
        summary << "; mean flicker " << (nFlicker ? sumFlicker / double(nFlicker) : 0.0) << ", min PSNR " << minPsnr
                << " dB, largest PSNR step between neighbours " << worstDrop << " dB";
        const std::string title = "vdbsplat animate " + fs::path(o.input).filename().string() + " — " +
                                  toString(o.settings.mode) + ", " + std::to_string(o.settings.camera.width) + "x" +
                                  std::to_string(o.settings.camera.height) + ", reference spp " +
                                  std::to_string(o.settings.spp);
        writeTextFileAtomic((dir / "plot.svg").string(), animation::plotSvg(present, title));
    }
    std::cout << summary.str() << "\n";
    if (o.mp4) {
        if (const auto ffmpeg = findOnPath("ffmpeg")) encodeMp4(*ffmpeg, dir, M, o.format, o.fps);
        else
            std::cerr << "vdbsplat: note: --mp4: ffmpeg is not on PATH, no animation.mp4 written (the frames are in "
                      << o.dir << "; install ffmpeg and run again with --resume --mp4)\n";
    }
    if (volume.nonFiniteCount)
        std::cerr << "vdbsplat: warning: " << o.input << ": " << volume.nonFiniteCount
                  << " active voxels with NaN or infinite values were treated as zero\n";
    return 0;
}

}  // namespace vdbsplat::cli
