// cli/cmd_study.cpp — `vdbsplat study`: a whole antialiasing study in one command.
// Owns: the study flags (declared here; the render flags through render_flags.h, minus --mode,
// --kernel and the camera placement, which the study varies), the plan (volumes × kernels × views × modes, every grid
// loaded once and every camera built before anything is written), the output folder protocol
// (refuse a non-empty folder without --resume/--force; every file atomic; a finished render is
// <stem>.exr + <stem>.png + <stem>.json, the JSON written last with the fingerprint of what
// made it, so --resume keeps exactly the renders whose fingerprint, size and files check out),
// the Ctrl-C/SIGTERM stop between and inside renders, and the summary line. The pictures,
// tables and plots are in study/.
//
// Kernels: each --kernels value is handed to the render flags' own parser as `--kernel NAME`
// (settingsFromFlags), so every kernel the render command accepts works here unchanged.
#include <CLI/App.hpp>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/interrupt.h"
#include "cli/render_flags.h"
#include "image/image.h"
#include "metrics/metrics.h"
#include "render/forward_buffers.h"
#include "render/render.h"
#include "study/error_map.h"
#include "study/report.h"
#include "study/spec.h"
#include "study/views.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"
#include "volume/emission.h"

namespace vdbsplat::cli {

namespace {

namespace fs = std::filesystem;
using study::View;

/// Render flags the study sets itself (per mode, per view) or replaces (--kernel → --kernels).
const std::set<std::string> kStudyOwned{"--mode", "--distance", "--eye", "--look-at", "--kernel"};
/// The forward modes a default study compares: those of this build that parseRenderMode accepts.
const char* const kCandidateModes[] = {"hybrid", "splat", "point", "ewa", "swan", "none"};
/// The kernel name when the settings JSON names none (the built-in Gaussian).
const char* const kBuiltInKernel = "gaussian";
constexpr size_t kMaxVolumes = 64, kMaxModes = 16, kMaxKernels = 8;
const char* const kDefaultSize = "200x200";

struct KernelPlan {
    std::string name;          ///< the folder and the report's label
    RenderSettings settings;   ///< every render flag and this kernel; mode and distance set per render
};

struct Options {
    std::vector<std::string> inputs;
    std::vector<std::string> tfs;  ///< the transfer function of each input (--tfs, else --tf for all)
    bool tfsGiven = false;
    std::string dir;
    std::vector<KernelPlan> kernels;
    std::vector<RenderMode> modes;
    std::vector<View> views;
    bool resume = false, force = false;
};

/// The render flags given to the study (with the study's default size), and @p kernel as
/// --kernel when given, through the render flags' parser (see the file comment).
RenderSettings settingsWithKernel(Args flags, const std::optional<std::string>& kernel) {
    if (!flags.has("--size")) flags.set("--size", kDefaultSize);
    if (kernel) flags.set("--kernel", *kernel);
    try {
        return settingsFromFlags(flags);
    } catch (const Error& e) {
        const std::string m = e.what();
        if (m.rfind("--kernel:", 0) == 0) throw Error("--kernels:" + m.substr(9));
        throw;
    }
}

std::string defaultKernelName(const RenderSettings& s) {
    const nlohmann::json j = s.toJson();
    return j.contains("kernel") && j["kernel"].is_string() ? j["kernel"].get<std::string>() : kBuiltInKernel;
}

std::vector<KernelPlan> kernelsFrom(const Args& args) {
    std::vector<KernelPlan> kernels;
    if (auto v = args.get("--kernels")) {
        for (const std::string& k : splitList(*v, "--kernels")) {
            for (const KernelPlan& p : kernels)
                if (p.name == k) throw Error("--kernels: '" + k + "' given more than once");
            if (study::safeId(k) != k) throw Error("--kernels: '" + printable(k) + "' is not a kernel name");
            kernels.push_back({k, settingsWithKernel(args, k)});
        }
        if (kernels.size() > kMaxKernels) throw Error("--kernels: at most " + std::to_string(kMaxKernels) + " kernels");
    } else {
        RenderSettings s = settingsWithKernel(args, std::nullopt);
        kernels.push_back({study::safeId(defaultKernelName(s)), s});
    }
    return kernels;
}

std::vector<RenderMode> modesFrom(const Args& args) {
    std::vector<std::string> names;
    if (auto v = args.get("--modes")) {
        names = splitList(*v, "--modes");
    } else {
        for (const char* c : kCandidateModes) try {
                (void)parseRenderMode(c);
                names.push_back(c);
            } catch (const Error&) {
            }
    }
    std::vector<RenderMode> modes;
    for (const std::string& n : names) {
        RenderMode m;
        try {
            m = parseRenderMode(n);
        } catch (const Error& e) {
            const std::string msg = e.what();
            throw Error("--modes:" + (msg.rfind("--mode:", 0) == 0 ? msg.substr(7) : " " + msg));
        }
        if (m == RenderMode::Reference)
            throw Error("--modes: 'reference' is rendered for every view anyway (leave it out)");
        if (std::find(modes.begin(), modes.end(), m) != modes.end()) throw Error("--modes: '" + n + "' given more than once");
        modes.push_back(m);
    }
    if (modes.size() > kMaxModes) throw Error("--modes: at most " + std::to_string(kMaxModes) + " modes");
    return modes;
}

std::vector<View> viewsFrom(const Args& args) {
    std::vector<View> views;
    bool ladder = false;
    if (auto v = args.get("--views")) {
        for (const std::string& item : splitList(*v, "--views")) {
            if (item == "standard") {
                for (const View& s : study::standardViews()) views.push_back(s);
            } else if (item == "ladder") {
                const double base = args.has("--base") ? parseDouble(*args.get("--base"), "--base") : 1.0;
                for (const View& s : study::zoomLadder(base)) views.push_back(s);
                ladder = true;
            } else {
                throw Error("--views: unknown views '" + printable(item) + "' (choose standard, ladder)");
            }
        }
    } else if (!args.has("--distances")) {
        views = study::standardViews();
    }
    if (args.has("--base") && !ladder) throw Error("--base: needs --views ladder");
    if (auto v = args.get("--distances"))
        for (const std::string& item : splitList(*v, "--distances")) {
            const double d = parseDouble(item, "--distances");
            if (!(d >= study::kMinDistance && d < 1e6))
                throw Error("--distances: each must be a number in [0.0001, 1e6), got '" + printable(item) + "'");
            views.push_back(study::viewAt(d));
        }
    views = study::withoutRepeats(views);
    // Far to close: the report, the CSV and the plots read in zoom order.
    std::stable_sort(views.begin(), views.end(), [](const View& a, const View& b) { return a.distance > b.distance; });
    if (views.size() > study::kMaxViews)
        throw Error("--views: at most " + std::to_string(study::kMaxViews) + " views in one study");
    return views;
}

Options optionsFrom(const Args& args) {
    Options o;
    o.inputs = args.positionals();
    if (o.inputs.empty()) throw Error("missing input .vdb file (see --help)");
    if (o.inputs.size() > kMaxVolumes) throw Error("at most " + std::to_string(kMaxVolumes) + " volumes in one study");
    o.dir = args.require("-o");
    if (o.dir.empty()) throw Error("-o: expected a folder, got ''");
    o.resume = args.has("--resume");
    o.force = args.has("--force");
    if (o.resume && o.force) throw Error("--resume: not with --force (choose one)");
    o.kernels = kernelsFrom(args);
    if (auto v = args.get("--tfs")) {
        if (args.has("--tf")) throw Error("--tfs: not with --tf (choose one)");
        o.tfs = splitList(*v, "--tfs");
        o.tfsGiven = true;
        if (o.tfs.size() != o.inputs.size())
            throw Error("--tfs: " + std::to_string(o.tfs.size()) + " transfer functions for " +
                        std::to_string(o.inputs.size()) + " volumes (give one per volume, in their order)");
    } else {
        o.tfs.assign(o.inputs.size(), o.kernels.front().settings.transferFunction);
    }
    o.modes = modesFrom(args);
    o.views = viewsFrom(args);
    return o;
}

// ---- the folder ---------------------------------------------------------------------------

bool nonEmptyFolder(const fs::path& dir) {
    std::error_code ec;
    return fs::is_directory(dir, ec) && fs::directory_iterator(dir, ec) != fs::directory_iterator();
}

/// The atomic writers' temporaries ("NAME.tmpPID" or "NAME.tmpPID.EXT") left by a killed run.
void removeTemporaries(const fs::path& dir) {
    static const std::regex re(R"(.*\.tmp[0-9]+(\.(png|exr))?)");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return;
    std::vector<fs::path> doomed;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
        if (it->is_regular_file(ec) && std::regex_match(it->path().filename().string(), re)) doomed.push_back(it->path());
    for (const auto& p : doomed) fs::remove(p, ec);
}

void prepareFolder(const Options& o) {
    const fs::path dir(o.dir);
    std::error_code ec;
    fs::create_directory(dir, ec);
    if (!fs::is_directory(dir)) throw Error("-o: " + o.dir + ": cannot create folder: " + ec.message());
    if (o.force) {
        fs::remove_all(dir / "images", ec);
        for (const char* name : {"index.html", "metrics.csv", "metrics.json", "command.txt"}) fs::remove(dir / name, ec);
    }
    removeTemporaries(dir);
}

void checkFolder(const Options& o) {
    const fs::path dir(o.dir);
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw Error("-o: " + o.dir + ": exists and is not a folder");
    if (!fs::exists(dir, ec)) {
        const fs::path parent = fs::absolute(dir, ec).parent_path();
        if (!fs::is_directory(parent, ec)) throw Error("-o: " + o.dir + ": parent folder does not exist");
    }
    if (nonEmptyFolder(dir) && !o.resume && !o.force)
        throw Error("-o: " + o.dir + ": folder is not empty (use --resume to continue it or --force to start afresh)");
}

std::string shellQuote(const std::string& a) {
    if (!a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./,=:+") ==
                          std::string::npos)
        return a;
    std::string q = "'";
    for (const char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string commandLine(const Argv& argv) {
    std::string c = "vdbsplat study";
    for (const std::string& a : argv) c += " " + shellQuote(a);
    return c;
}

// ---- one render, made or kept -------------------------------------------------------------

struct Rendered {
    Image image;
    double seconds = 0.0;
    uint64_t points = 0, splats = 0;
    bool kept = false;
};

/// What determines a render's pixels besides the settings: the file (path, size, time) and grid.
nlohmann::json volumeIdentity(const std::string& input, const Volume& volume) {
    std::error_code ec;
    const fs::path canon = fs::weakly_canonical(input, ec);
    const auto size = fs::file_size(input, ec);
    const auto time = fs::last_write_time(input, ec).time_since_epoch().count();
    return {{"input", canon.string()}, {"bytes", uint64_t(size)}, {"mtime", int64_t(time)}, {"grid", volume.name}};
}

/// The fingerprinted description of one render: the volume and the settings that change its
/// pixels (the reference ignores the forward modes' knobs; the forward modes ignore --spp), each
/// written even at its default (identityJson): a render of an older build made at another default
/// (--cutoff 1e-4 before session 40) is rendered again, not kept.
nlohmann::json renderIdentity(const nlohmann::json& volume, const RenderSettings& s) {
    nlohmann::json settings = s.identityJson();
    if (s.mode == RenderMode::Reference) {
        for (const char* k : {"threshold", "footprint", "filter_order", "subpixels", "lod", "simd", "show_primitives", "tables"})
            settings.erase(k);
    } else {
        settings.erase("spp");
    }
    return {{"volume", volume}, {"settings", settings}};
}

std::optional<Rendered> keptRender(const fs::path& stem, const std::string& hash, const RenderSettings& s) {
    const fs::path exr = stem.string() + ".exr", png = stem.string() + ".png", side = stem.string() + ".json";
    std::error_code ec;
    if (!fs::is_regular_file(side, ec) || !fs::is_regular_file(exr, ec)) return std::nullopt;
    try {
        std::ifstream in(side, std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        const nlohmann::json j = nlohmann::json::parse(text.str());
        if (j.at("fingerprint").get<std::string>() != hash || j.at("width").get<int>() != s.camera.width ||
            j.at("height").get<int>() != s.camera.height)
            return std::nullopt;
        Rendered r;
        r.image = readImage(exr.string());
        if (r.image.width != s.camera.width || r.image.height != s.camera.height) return std::nullopt;
        r.seconds = j.at("seconds").get<double>();
        r.points = j.at("points").get<uint64_t>();
        r.splats = j.at("splats").get<uint64_t>();
        r.kept = true;
        bool pngOk = false;
        try {
            const Image p = readImage(png.string());
            pngOk = p.width == s.camera.width && p.height == s.camera.height;
        } catch (const Error&) {
        }
        if (!pngOk) writeImage(png.string(), r.image);  // the viewing copy, from the exact one
        return r;
    } catch (const std::exception&) {  // a damaged record or image: render it again
        return std::nullopt;
    }
}

Rendered makeRender(const fs::path& stem, const std::string& hash, const nlohmann::json& identity, const Volume& volume,
                    const TransferFunction& tf, const RenderSettings& requested, const Camera& camera,
                    const RenderControl& control) {
    const RenderSettings s = resolvedFor(volume, camera, requested);  // --subpixels auto: the k used
    RenderStats st;
    Rendered r;
    WindowedImage image = renderWindowed(volume, tf, s, st, control);  // timed as `vdbsplat render` times it
    r.image = image.full();
    if (control.buffers) control.buffers->recycle(std::move(image));  // its memory for the next render
    r.seconds = st.seconds;
    r.points = st.points;
    r.splats = st.splats;
    writeImage(stem.string() + ".exr", r.image,
               {{"settings", s.toJson().dump()}, {"camera", camera.describe()}, {"mode", toString(s.mode)}});
    writeImage(stem.string() + ".png", r.image);
    const nlohmann::json side = {{"fingerprint", hash}, {"width", s.camera.width}, {"height", s.camera.height},
                                 {"seconds", st.seconds}, {"points", st.points}, {"splats", st.splats},
                                 {"made_from", identity}, {"stats", st.toJson()}, {"camera", camera.describe()}};
    writeTextFileAtomic(stem.string() + ".json", side.dump(2) + "\n");  // last: marks the render finished
    return r;
}

// ---- the run ------------------------------------------------------------------------------

struct LoadedVolume {
    std::string input, id;
    Volume volume;
    nlohmann::json identity;
    std::string tfSpec;  ///< RenderSettings::transferFunction of its renders
    TransferFunction tf;
};

/// The transfer function of volume @p i; @throw Error naming --tfs or --tf.
TransferFunction transferFunctionOf(const Options& o, size_t i) {
    RenderSettings s = o.kernels.front().settings;
    s.transferFunction = o.tfs[i];
    try {
        return transferFunctionFor(s);
    } catch (const Error& e) {
        if (!o.tfsGiven) throw;
        const std::string m = e.what();  // "--tf: …"
        throw Error("--tfs" + m.substr(m.find(':')));
    }
}

/// File-safe, unique ids from the file names ("engine", "engine-2" for a second engine.vdb).
std::vector<std::string> volumeIds(const std::vector<std::string>& inputs) {
    std::vector<std::string> ids;
    for (const std::string& in : inputs) {
        const std::string base = study::safeId(fs::path(in).stem().string());
        std::string id = base;
        for (int k = 2; std::find(ids.begin(), ids.end(), id) != ids.end(); ++k) id = base + "-" + std::to_string(k);
        ids.push_back(id);
    }
    return ids;
}

std::vector<LoadedVolume> loadVolumes(const Options& o) {
    std::set<std::string> seen;
    const auto ids = volumeIds(o.inputs);
    std::vector<LoadedVolume> out;
    for (size_t i = 0; i < o.inputs.size(); ++i) {
        std::error_code ec;
        const std::string canon = fs::weakly_canonical(o.inputs[i], ec).string();
        if (!seen.insert(canon).second) throw Error(o.inputs[i] + ": given more than once");
        const RenderSettings& s = o.kernels.front().settings;
        LoadedVolume lv{o.inputs[i], ids[i], loadVolumeWithEmission(o.inputs[i], s.gridName, s.emission.grid), {},
                        o.tfs[i], transferFunctionOf(o, i)};
        lv.identity = volumeIdentity(o.inputs[i], lv.volume);
        for (const KernelPlan& k : o.kernels) checkVoxelBudget(lv.volume, k.settings);
        out.push_back(std::move(lv));
    }
    return out;
}

struct Counters {
    size_t total = 0, done = 0, rendered = 0, kept = 0;
    bool warmedUp = false;
};

/// One small untimed render per mode before the first timed one: the first render of a process
/// pays for starting the worker threads and first-touching memory, which would otherwise land on
/// whichever cell comes first (measured: 0.71 s against 0.32 s for the same splat render).
void warmUp(const Options& o, const LoadedVolume& lv, const KernelPlan& k, const View& view,
            const RenderControl& control) {
    std::vector<RenderMode> modes = o.modes;
    modes.push_back(RenderMode::Reference);
    for (RenderMode m : modes) {
        RenderSettings s = k.settings;
        s.mode = m;
        s.spp = 1;
        s.camera.distance = view.distance;
        s.camera.width = s.camera.height = 32;
        RenderStats st;
        s.transferFunction = lv.tfSpec;
        (void)render(lv.volume, lv.tf, s, st, control);
    }
}

std::string relativeTo(const fs::path& p, const fs::path& dir) { return fs::relative(p, dir).generic_string(); }

/// Reference and modes of one view: renders (or keeps) them, writes the derived pictures.
study::ViewResult runView(const Options& o, const LoadedVolume& lv, const KernelPlan& k,
                          const View& view, const fs::path& folder, const RenderControl& control, Counters& n,
                          const InterruptGuard& guard) {
    const fs::path root(o.dir);
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (!fs::is_directory(folder)) throw Error(folder.string() + ": cannot create folder: " + ec.message());
    auto one = [&](RenderMode mode, const std::string& name) {
        RenderSettings s = k.settings;
        s.mode = mode;
        s.camera.distance = view.distance;
        s.transferFunction = lv.tfSpec;
        const Camera camera = cameraFor(lv.volume, s);
        const nlohmann::json identity = renderIdentity(lv.identity, s);
        const std::string hash = study::fnv1a(identity.dump());
        const fs::path stem = folder / name;
        std::optional<Rendered> r = o.resume ? keptRender(stem, hash, s) : std::nullopt;
        if (!r && !n.warmedUp) {
            warmUp(o, lv, k, view, control);
            n.warmedUp = true;
        }
        if (!r) r = makeRender(stem, hash, identity, lv.volume, lv.tf, s, camera, control);
        ++(r->kept ? n.kept : n.rendered);
        ++n.done;
        if (::isatty(2) == 1)
            std::fprintf(stderr, "\r[%zu/%zu] %s %s %s %-9s %s   ", n.done, n.total, lv.id.c_str(), k.name.c_str(),
                         view.id.c_str(), name.c_str(), r->kept ? "kept" : "rendered");
        if (guard.interrupted()) throw RenderStopped("stopped");
        return *r;
    };
    study::ViewResult vr;
    vr.view = view;
    const Rendered ref = one(RenderMode::Reference, "reference");
    vr.referenceSeconds = ref.seconds;
    vr.referenceImage = relativeTo(folder / "reference.png", root);
    std::vector<Rendered> renders;
    std::vector<std::vector<double>> errors;
    for (RenderMode m : o.modes) {
        renders.push_back(one(m, toString(m)));
        errors.push_back(study::pixelErrors(renders.back().image, ref.image));
    }
    vr.crop = study::worstWindow(errors, ref.image.width, ref.image.height);
    writeImage((folder / "reference-crop.png").string(), study::crop(ref.image, vr.crop));
    vr.referenceCrop = relativeTo(folder / "reference-crop.png", root);
    for (size_t i = 0; i < o.modes.size(); ++i) {
        const std::string name = toString(o.modes[i]);
        study::ModeResult m;
        m.mode = name;
        m.metrics = compareImages(renders[i].image, ref.image);
        m.seconds = renders[i].seconds;
        m.points = renders[i].points;
        m.splats = renders[i].splats;
        writeImage((folder / (name + "-error.png")).string(), study::heatMap(errors[i], ref.image.width, ref.image.height));
        writeImage((folder / (name + "-crop.png")).string(), study::crop(renders[i].image, vr.crop));
        m.image = relativeTo(folder / (name + ".png"), root);
        m.errorImage = relativeTo(folder / (name + "-error.png"), root);
        m.cropImage = relativeTo(folder / (name + "-crop.png"), root);
        vr.modes.push_back(m);
    }
    return vr;
}

void appendCommand(const fs::path& dir, const std::string& command) {
    std::string previous;
    if (std::ifstream in(dir / "command.txt", std::ios::binary); in) {
        std::ostringstream s;
        s << in.rdbuf();
        previous = s.str();
    }
    if (!previous.empty() && previous.back() != '\n') previous += "\n";
    writeTextFileAtomic((dir / "command.txt").string(), previous + command + "\n");
}

/// The study's flags with --spec FILE replaced by the arguments the file stands for (its volumes
/// first), parsed again by the study's own declarations. @p fromSpec receives flag → key for
/// the flags the file gave.
/// @throw Error naming the file for a bad file, or a setting given both there and as a flag.
Args withSpec(const Args& args, std::map<std::string, std::string>& fromSpec) {
    const Argv& argv = args.words();
    const auto spec = args.get("--spec");
    if (spec->empty()) throw Error("--spec: expected a file name, got ''");
    Argv volumes, flags;
    for (const study::SpecArgument& a : study::loadSpec(*spec)) {
        if (a.key == "volumes") {
            if (!args.positionals().empty())
                throw Error(*spec + ": volumes: also given on the command line (give them in one place)");
            volumes = a.args;
            continue;
        }
        if (args.has(a.args.front()))
            throw Error(*spec + ": " + a.key + ": also given as " + a.args.front() + " on the command line");
        fromSpec[a.args.front()] = a.key;
        flags.insert(flags.end(), a.args.begin(), a.args.end());
    }
    Argv out = volumes;
    out.insert(out.end(), flags.begin(), flags.end());
    for (size_t i = 0; i < argv.size(); ++i) {
        if (argv[i] == "--spec") { ++i; continue; }
        if (argv[i].rfind("--spec=", 0) == 0) continue;
        out.push_back(argv[i]);
    }
    CLI::App again;
    declareStudy(again);
    return parseAlone(again, out);
}

/// optionsFrom, with a bad value that came from the study file named by the file and its key.
Options optionsWithSpec(const Args& args, const std::map<std::string, std::string>& fromSpec, const std::string& spec) {
    try {
        return optionsFrom(args);
    } catch (const Error& e) {
        const std::string m = e.what();  // "--flag: …" or "--flag width: …"
        const std::string flag = m.substr(0, m.find_first_of(": "));
        if (const auto it = fromSpec.find(flag); it != fromSpec.end())
            throw Error(spec + ": " + it->second + m.substr(flag.size()));
        throw;
    }
}

}  // namespace

void declareStudy(CLI::App& app) {
    app.description(
        "antialiasing study: every mode and view against the reference, HTML report\n"
        "\n"
        "usage: vdbsplat study FILE.vdb [FILE.vdb ...] -o DIR [options]\n"
        "\n"
        "Runs an antialiasing study: every volume (each loaded once), kernel and view is rendered by\n"
        "the reference (once, shared by the modes) and by every mode; DIR receives index.html (image\n"
        "grid per view, error heat maps with a colour bar, crops of the worst window, PSNR/SSIM/time\n"
        "against zoom plots, the metrics table; self-contained), metrics.csv, metrics.json,\n"
        "command.txt and the images under DIR/images/VOLUME/KERNEL/VIEW/ (MODE.png for viewing,\n"
        "MODE.exr for the metrics, MODE.json: what made it; MODE-error.png, MODE-crop.png).\n"
        "The render flags are as for vdbsplat render, the same for every mode and view.");
    addPositional(app, "FILE.vdb", "the volumes to study (or from --spec)", true);
    addValueFlag(app, "-o", "DIR", "output folder (created; its parent must exist). A non-empty DIR is\n"
                                   "refused unless --resume or --force is given")
        ->required();
    addValueFlag(app, "--modes", "LIST", "comma-separated forward modes as --mode takes them (default: every\n"
                                         "forward mode of this build: hybrid, splat, point, ewa, swan, none)");
    addValueFlag(app, "--kernels", "LIST", "reconstruction kernels as render's --kernel takes them (default:\n"
                                           "the render default); the reference of each kernel uses that kernel");
    addValueFlag(app, "--views", "LIST", "standard (distance 8, 1, 0.35) and/or ladder (zoom 1/8x, 1/4x,\n"
                                         "1/2x, 1x, 2x, 4x, 8x: distance --base / zoom); default standard");
    addValueFlag(app, "--base", "K", "the ladder's 1x framing distance (default 1)");
    addValueFlag(app, "--distances", "LIST", "further views at these framing distances (alone: only these)");
    addValueFlag(app, "--tfs", "LIST", "one transfer function per volume, in their order (instead of --tf:\n"
                                       "e.g. grey,grey,ct-bone for two generated volumes and a CT)");
    addSwitch(app, "--resume", "keep the finished renders in DIR whose settings fingerprint, size and\n"
                               "files check out, render the rest (changed settings: only what they\n"
                               "change)");
    addSwitch(app, "--force", "start afresh in a non-empty DIR (removes images/, index.html,\n"
                              "metrics.*, command.txt)");
    addValueFlag(app, "--spec", "FILE.json", "the study's volumes and settings from a file (docs/usage.md,\n"
                                             "\"study\"): {\"volumes\": [...], \"modes\": [...], \"views\": [...],\n"
                                             "\"size\": [W, H], ...}; flags on the command line add to it (not\n"
                                             "the same setting twice)");
    addRenderFlags(app, kStudyOwned);
    app.footer(
        "Ctrl-C or SIGTERM stops within the render under way (a second one stops at once): the\n"
        "finished renders stay, nothing is half-written, exit 1; run again with --resume.\n"
        "Prints a summary line on stdout (renders made and kept).");
}

int runStudy(const Args& given) {
    std::map<std::string, std::string> fromSpec;
    const Args args = given.has("--spec") ? withSpec(given, fromSpec) : given;
    const Options o = optionsWithSpec(args, fromSpec, given.getOr("--spec", ""));
    checkFolder(o);
    const RenderSettings& base = o.kernels.front().settings;
    std::unique_ptr<tbb::global_control> threads;
    if (base.threads > 0)
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, base.threads);
    InterruptGuard guard;  // before loading: a Ctrl-C while loading stops before anything is written
    const std::vector<LoadedVolume> volumes = loadVolumes(o);
    // Every camera is built (and so validated) before anything is written.
    for (const LoadedVolume& lv : volumes)
        for (const KernelPlan& k : o.kernels)
            for (const View& v : o.views) {
                RenderSettings s = k.settings;
                s.camera.distance = v.distance;
                try {
                    (void)cameraFor(lv.volume, s);
                } catch (const Error& e) {
                    throw Error(lv.input + ": view " + v.label + ": " + e.what());
                }
            }
    if (guard.interrupted()) throw Error("interrupted (" + guard.signalName() + ") before the study started");

    prepareFolder(o);
    const fs::path dir(o.dir);
    const std::string command = commandLine(given.words());
    appendCommand(dir, command);

    study::StudyResult result;
    result.command = command;
    result.width = base.camera.width;
    result.height = base.camera.height;
    result.spp = base.spp;
    result.tf = o.tfsGiven ? "per volume" : base.transferFunction;
    for (RenderMode m : o.modes) result.modes.push_back(toString(m));
    for (const KernelPlan& k : o.kernels) result.kernels.push_back(k.name);
    result.settings = base.toJson();
    result.settings.erase("mode");
    result.settings.erase("distance");

    Counters n;
    n.total = volumes.size() * o.kernels.size() * o.views.size() * (o.modes.size() + 1);
    RenderControl control;
    control.stop = [&guard] { return guard.interrupted(); };
    ForwardBuffers buffers;  // kept from render to render (render/forward_buffers.h)
    control.buffers = &buffers;
    const auto start = std::chrono::steady_clock::now();
    try {
        for (const LoadedVolume& lv : volumes) {
            study::VolumeResult vol{lv.id, lv.input, lv.volume.name, lv.volume.activeVoxels, lv.tfSpec, {}};
            for (const KernelPlan& k : o.kernels) {
                study::KernelResult kr{k.name, {}};
                for (const View& v : o.views)
                    kr.views.push_back(runView(o, lv, k, v, dir / "images" / lv.id / k.name / v.id, control, n, guard));
                vol.kernels.push_back(std::move(kr));
            }
            result.volumes.push_back(std::move(vol));
        }
    } catch (const RenderStopped&) {
        if (::isatty(2) == 1) std::fprintf(stderr, "\n");
        throw Error("interrupted (" + guard.signalName() + ") after " + std::to_string(n.done) + " of " +
                    std::to_string(n.total) + " renders (the finished ones are kept: run again with --resume)");
    }
    if (::isatty(2) == 1) std::fprintf(stderr, "\n");

    writeTextFileAtomic((dir / "metrics.csv").string(), study::metricsCsv(result));
    writeTextFileAtomic((dir / "metrics.json").string(), study::metricsJson(result).dump(2) + "\n");
    writeTextFileAtomic((dir / "index.html").string(), study::reportHtml(result));  // last: the study is complete

    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "study: " << volumes.size() << " volume" << (volumes.size() == 1 ? "" : "s") << " x "
              << o.kernels.size() << " kernel" << (o.kernels.size() == 1 ? "" : "s") << " x " << o.views.size()
              << " view" << (o.views.size() == 1 ? "" : "s") << " x (reference + " << o.modes.size() << " mode"
              << (o.modes.size() == 1 ? "" : "s") << "): " << n.total << " renders (" << n.rendered << " rendered, "
              << n.kept << " kept) in " << durationText(seconds) << "; report " << (dir / "index.html").string()
              << "\n";
    for (const LoadedVolume& lv : volumes)
        if (lv.volume.nonFiniteCount)
            std::cerr << "vdbsplat: warning: " << lv.input << ": " << lv.volume.nonFiniteCount
                      << " active voxels with NaN or infinite values were treated as zero\n";
    return 0;
}

}  // namespace vdbsplat::cli
