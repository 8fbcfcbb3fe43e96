// cli/cmd_bench.cpp — `vdbsplat bench`: times the forward modes at the standard views.
// Owns: the benchmark protocol (load the volume and transfer function once, then
// for each run round, for each distance, for each mode, call render() — the same
// entry point as `vdbsplat render` — so machine drift hits every mode alike), its
// statistics (median/min seconds, per-stage medians, primitive counts, ratio of
// each mode's median to hybrid's at the same distance and the median of those
// ratios over distances), the fixed-width table in the manner of Yuan et al. 2003,
// Figure 9, and the optional JSON report (written atomically). It is a benchmark,
// not a test: nothing here judges the numbers.
#include <CLI/App.hpp>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/render_flags.h"
#include "volume/emission.h"
#include "render/forward_buffers.h"
#include "render/render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::cli {

namespace {

/// Render flags bench does not take: it varies the mode and the distance itself (--modes,
/// --distances), always frames the grid (--fov still sets the lens), and writes no image.
const std::set<std::string> kNotBenchFlags{"--mode", "--distance", "--eye", "--look-at", "--show-primitives"};

constexpr int kMaxRuns = 1000;
constexpr int kMaxWarmup = 100;
constexpr size_t kMaxDistances = 32;

std::vector<RenderMode> parseModes(const std::string& text) {
    std::vector<RenderMode> modes;
    for (const std::string& item : splitList(text, "--modes")) {
        RenderMode mode;
        try {
            mode = parseRenderMode(item);
        } catch (const Error&) {
            throw Error("--modes: unknown mode '" + item + "' (choose " + kRenderModeNames + ")");
        }
        if (std::find(modes.begin(), modes.end(), mode) != modes.end())
            throw Error("--modes: '" + item + "' given more than once");
        modes.push_back(mode);
    }
    return modes;
}

std::vector<double> parseDistances(const std::string& text) {
    std::vector<double> distances;
    for (const std::string& item : splitList(text, "--distances")) {
        const double d = parseDouble(item, "--distances");
        if (!(d > 0.0 && d < 1e6)) throw Error("--distances: each must be a positive number below 1e6, got '" + item + "'");
        if (std::find(distances.begin(), distances.end(), d) != distances.end())
            throw Error("--distances: '" + item + "' given more than once");
        distances.push_back(d);
    }
    if (distances.size() > kMaxDistances)
        throw Error("--distances: at most " + std::to_string(kMaxDistances) + " distances");
    return distances;
}

struct Options {
    std::string input;
    RenderSettings base;  ///< everything but mode and distance
    std::vector<RenderMode> modes{RenderMode::Hybrid, RenderMode::Splat, RenderMode::Point};
    std::vector<double> distances{8.0, 1.0, 0.35};
    int runs = 5;
    int warmup = 1;
    std::optional<std::string> json;
    bool verbose = false;

    RenderSettings settingsFor(double distance, RenderMode mode) const {
        RenderSettings s = base;
        s.mode = mode;
        s.camera.distance = distance;
        return s;
    }
};

Options optionsFrom(const Args& args) {
    Options o;
    o.input = args.onePositional("input .vdb file");
    o.base = settingsFromFlags(args);  // the render flags bench declares (kNotBenchFlags aside)
    if (auto v = args.get("--runs")) o.runs = int(parseInt(*v, "--runs", 1, kMaxRuns));
    if (auto v = args.get("--warmup")) o.warmup = int(parseInt(*v, "--warmup", 0, kMaxWarmup));
    if (auto v = args.get("--modes")) o.modes = parseModes(*v);
    if (auto v = args.get("--distances")) o.distances = parseDistances(*v);
    o.json = args.get("--json");
    o.verbose = args.has("-v");
    // The same validation as `render`, for every combination that will run.
    for (double d : o.distances)
        for (RenderMode m : o.modes) o.settingsFor(d, m).validate();
    if (o.json) {
        const std::filesystem::path dir = std::filesystem::path(*o.json).parent_path();
        std::error_code ec;
        if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) throw Error(*o.json + ": folder does not exist");
        checkOutputPath(*o.json);  // a directory or dangling link fails before the benchmark
        checkNotAnInput(*o.json, o.input, "--json");
    }
    return o;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Everything measured for one (distance, mode).
struct Cell {
    double distance = 0.0;
    RenderMode mode = RenderMode::Hybrid;
    std::vector<double> seconds, stream, project, rasterize, composite;
    RenderStats first;  ///< counts of the first timed run (the primitive counts do not vary between runs)
    std::optional<double> ratio;  ///< median / hybrid's median at the same distance

    double medianSeconds() const { return median(seconds); }
    double minSeconds() const { return *std::min_element(seconds.begin(), seconds.end()); }
    std::optional<double> splatFraction() const {
        const uint64_t drawn = first.points + first.splats;
        if (!drawn) return std::nullopt;
        return double(first.splats) / double(drawn);
    }
};

nlohmann::ordered_json optionalJson(const std::optional<double>& v) {
    return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(nullptr);
}

std::string formatDistance(double d) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", d);
    return buf;
}

}  // namespace

void declareBench(CLI::App& app) {
    app.description(
        "time hybrid, splat-only and point-only at the standard views\n"
        "\n"
        "usage: vdbsplat bench FILE.vdb [options]\n"
        "\n"
        "Renders FILE at the standard views (--distance 8 far, 1 framed, 0.35 close) in hybrid,\n"
        "splat-only and point-only mode, several runs each, and prints, per view and mode, the\n"
        "median and minimum seconds of a render (as `vdbsplat render -v` reports it), the share of\n"
        "splats among drawn primitives, and the ratio of the mode's median to hybrid's at that view;\n"
        "then the median of those ratios over the views. Runs are interleaved (for each run: for\n"
        "each view: for each mode) so machine drift affects every mode alike. A benchmark, not a test.");
    addPositional(app, "FILE.vdb", "the volume to render");
    addValueFlag(app, "--runs", "N", "timed runs per view and mode, 1..1000 (default 5)");
    addValueFlag(app, "--warmup", "N", "untimed rounds before them, 0..100 (default 1)");
    addValueFlag(app, "--modes", "LIST", "comma-separated, from hybrid, splat, point, ewa, swan, none,\n"
                                         "reference (default hybrid,splat,point; reference is slow)");
    addValueFlag(app, "--distances", "LIST", "comma-separated framing distances (default 8,1,0.35)");
    addValueFlag(app, "--json", "FILE.json", "also write every run, the per-stage medians and the ratios as\n"
                                             "JSON");
    addSwitch(app, "-v", "print each run to stderr and the per-stage medians to stdout");
    addRenderFlags(app, kNotBenchFlags);
}

int runBench(const Args& args) {
    const Options o = optionsFrom(args);

    std::unique_ptr<tbb::global_control> limit;
    if (o.base.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.base.threads);
    const int threads = std::min<int>(tbb::this_task_arena::max_concurrency(),
                                      int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
    const unsigned machine = std::thread::hardware_concurrency();

    const TransferFunction tf = TransferFunction::fromSpec(o.base.transferFunction);
    const Volume volume = loadVolumeWithEmission(o.input, o.base.gridName, o.base.emission.grid);
    for (double d : o.distances) cameraFor(volume, o.settingsFor(d, RenderMode::Hybrid));  // validates before the work

    if (std::find(o.modes.begin(), o.modes.end(), RenderMode::Reference) != o.modes.end())
        std::cerr << "vdbsplat: warning: reference mode traces " << o.base.spp
                  << " rays per pixel and is far slower than the forward modes\n";
    if (volume.nonFiniteCount)
        std::cerr << "vdbsplat: warning: " << o.input << ": " << volume.nonFiniteCount
                  << " active voxels with NaN or infinite values were treated as zero\n";

    // cells[di * modes + mi]
    std::vector<Cell> cells;
    for (double d : o.distances)
        for (RenderMode m : o.modes) cells.push_back(Cell{d, m, {}, {}, {}, {}, {}, {}, std::nullopt});

    // The renders keep their buffers from one to the next, as animate and study do: a run's
    // time is the render's, not the first touch of ~40 MB of fresh memory (forward_buffers.h).
    ForwardBuffers buffers;
    RenderControl control;
    control.buffers = &buffers;
    const int rounds = o.warmup + o.runs;
    for (int r = 0; r < rounds; ++r) {
        const bool timed = r >= o.warmup;
        for (size_t di = 0; di < o.distances.size(); ++di)
            for (size_t mi = 0; mi < o.modes.size(); ++mi) {
                Cell& cell = cells[di * o.modes.size() + mi];
                RenderStats stats;
                buffers.recycle(renderWindowed(volume, tf, o.settingsFor(cell.distance, cell.mode), stats, control));
                if (o.verbose)
                    std::fprintf(stderr, "%s %d/%d  distance %-6s %-9s %.4f s\n", timed ? "run   " : "warmup",
                                 timed ? r - o.warmup + 1 : r + 1, timed ? o.runs : o.warmup,
                                 formatDistance(cell.distance).c_str(), toString(cell.mode).c_str(), stats.seconds);
                if (!timed) continue;
                if (cell.seconds.empty()) cell.first = stats;
                cell.seconds.push_back(stats.seconds);
                cell.stream.push_back(stats.streamSeconds);
                cell.project.push_back(stats.projectSeconds);
                cell.rasterize.push_back(stats.rasterizeSeconds);
                cell.composite.push_back(stats.compositeSeconds);
            }
    }

    // Ratios to hybrid, per distance, then their median over distances per mode.
    const auto hybridIt = std::find(o.modes.begin(), o.modes.end(), RenderMode::Hybrid);
    std::vector<std::pair<RenderMode, std::optional<double>>> overall;
    for (size_t mi = 0; mi < o.modes.size(); ++mi) {
        if (o.modes[mi] == RenderMode::Hybrid) continue;
        std::vector<double> ratios;
        if (hybridIt != o.modes.end()) {
            const size_t hi = size_t(hybridIt - o.modes.begin());
            for (size_t di = 0; di < o.distances.size(); ++di) {
                Cell& cell = cells[di * o.modes.size() + mi];
                const double hybrid = cells[di * o.modes.size() + hi].medianSeconds();
                if (hybrid > 0.0) {
                    cell.ratio = cell.medianSeconds() / hybrid;
                    ratios.push_back(*cell.ratio);
                }
            }
        }
        overall.emplace_back(o.modes[mi], ratios.empty() ? std::nullopt : std::optional<double>(median(ratios)));
    }

    // The table.
    std::printf("vdbsplat bench: %s (grid '%s', %llu active voxels), %dx%d, fov %g, tf %s, threshold %g px, footprint %s, %s (%s subpixels)\n",
                o.input.c_str(), volume.name.c_str(), (unsigned long long)volume.activeVoxels, o.base.camera.width,
                o.base.camera.height, o.base.camera.fovDeg, o.base.transferFunction.c_str(), o.base.threshold,
                toString(o.base.footprint).c_str(), toString(o.base.filterOrder).c_str(),
                o.base.subpixels == kAutoSubpixels ? "auto" : std::to_string(o.base.subpixels).c_str());
    std::printf("threads %d (machine %u), %d timed run%s + %d warmup per view and mode, interleaved\n\n", threads,
                machine, o.runs, o.runs == 1 ? "" : "s", o.warmup);
    std::printf("%8s  %-9s  %9s  %9s  %8s  %15s  %10s  %10s  %10s\n", "distance", "mode", "median_s", "min_s", "%splats",
                "ratio_to_hybrid", "points", "splats", "culled");
    for (size_t i = 0; i < cells.size(); ++i) {
        const Cell& c = cells[i];
        if (i && i % o.modes.size() == 0) std::printf("\n");
        const auto frac = c.splatFraction();
        char fracText[16] = "-", ratioText[16] = "-";
        if (frac) std::snprintf(fracText, sizeof fracText, "%.1f%%", 100.0 * *frac);
        if (c.ratio) std::snprintf(ratioText, sizeof ratioText, "%.2fx", *c.ratio);
        std::printf("%8s  %-9s  %9.4f  %9.4f  %8s  %15s  %10llu  %10llu  %10llu\n", formatDistance(c.distance).c_str(),
                    toString(c.mode).c_str(), c.medianSeconds(), c.minSeconds(), fracText, ratioText,
                    (unsigned long long)c.first.points, (unsigned long long)c.first.splats,
                    (unsigned long long)c.first.culled);
    }
    if (!overall.empty()) {
        std::printf("\nmedian over distances of median(mode) / median(hybrid):");
        for (const auto& [mode, ratio] : overall) {
            if (ratio) std::printf("  %s %.2fx", toString(mode).c_str(), *ratio);
            else std::printf("  %s -", toString(mode).c_str());
        }
        std::printf("\n");
    }
    if (o.verbose) {
        std::printf("\nmedian stage seconds\n%8s  %-9s  %9s  %9s  %9s  %9s\n", "distance", "mode", "stream", "project",
                    "rasterize", "composite");
        for (const Cell& c : cells)
            std::printf("%8s  %-9s  %9.4f  %9.4f  %9.4f  %9.4f\n", formatDistance(c.distance).c_str(),
                        toString(c.mode).c_str(), median(c.stream), median(c.project), median(c.rasterize),
                        median(c.composite));
    }
    std::fflush(stdout);

    if (o.json) {
        nlohmann::ordered_json j;
        j["volume"] = o.input;
        j["grid"] = volume.name;
        j["active_voxels"] = volume.activeVoxels;
        j["width"] = o.base.camera.width;
        j["height"] = o.base.camera.height;
        j["threads"] = threads;
        j["machine"] = machine;
        j["runs"] = o.runs;
        j["warmup"] = o.warmup;
        j["tf"] = o.base.transferFunction;
        j["threshold"] = o.base.threshold;
        j["footprint"] = toString(o.base.footprint);
        j["filter_order"] = toString(o.base.filterOrder);
        j["subpixels"] = o.base.subpixels == kAutoSubpixels ? nlohmann::json("auto") : nlohmann::json(o.base.subpixels);
        j["fov"] = o.base.camera.fovDeg;
        j["spp"] = o.base.spp;
        j["tables"] = o.base.tablesDir;  // "": the shipped tables
        j["max_voxels"] = o.base.maxActiveVoxels;
        nlohmann::ordered_json results = nlohmann::ordered_json::array();
        for (const Cell& c : cells) {
            nlohmann::ordered_json r;
            r["distance"] = c.distance;
            r["mode"] = toString(c.mode);
            r["median_seconds"] = c.medianSeconds();
            r["min_seconds"] = c.minSeconds();
            r["seconds"] = c.seconds;
            r["splat_fraction"] = optionalJson(c.splatFraction());
            r["points"] = c.first.points;
            r["splats"] = c.first.splats;
            r["culled"] = c.first.culled;
            if (c.first.rays) r["rays"] = c.first.rays;
            r["stages"] = {{"stream", median(c.stream)},
                           {"project", median(c.project)},
                           {"rasterize", median(c.rasterize)},
                           {"composite", median(c.composite)}};
            r["ratio_to_hybrid"] = optionalJson(c.ratio);
            results.push_back(r);
        }
        j["results"] = results;
        nlohmann::ordered_json ratios = nlohmann::ordered_json::object();
        for (const auto& [mode, ratio] : overall) ratios[toString(mode)] = optionalJson(ratio);
        j["ratios"] = ratios;
        writeTextFileAtomic(*o.json, j.dump(2) + "\n");
    }
    return 0;
}

}  // namespace vdbsplat::cli
