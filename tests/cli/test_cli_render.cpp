// tests/cli/test_cli_render.cpp — `vdbsplat render` run as the real binary.
// Bad input, in every mode it applies to (hybrid, splat, point, reference): a non-zero
// exit, exactly one stderr line "vdbsplat: error: …" naming the file or flag, and an
// output folder left empty (no image, no temporary). A failed render never clobbers an
// existing image. Good renders: each mode to PNG and EXR, the --stats JSON, the image
// independent of --threads and of --tables (shipped, a copy, or built in memory).
//
// Every run is a separate process (start-up ≈ 0.1 s of CPU each; 0.5 s while the image
// library was OpenImageIO, with some 260 shared libraries), so the runs of a test go through a small pool of
// threads, and a bad value that the flag parser rejects before the mode is looked at
// runs in one mode, rotating over the four (VDBSPLAT_TEST_ALL_MODES=1 runs it in all).
#include <gtest/gtest.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <openvdb/io/File.h>
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "image/image.h"
#include "support/cli.h"
#include "volume/generate.h"
#include "volume/grid.h"

extern char** environ;

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::slurp;
using test::spit;

const std::vector<std::string> kAllModes = {"hybrid", "splat", "point", "ewa", "swan", "none", "reference"};
const std::vector<std::string> kForwardModes = {"hybrid", "splat", "point", "ewa", "swan", "none"};

using Result = test::CliResult;

/// Runs `vdbsplat ARGS…` (no shell), stdout and stderr captured through files in @p logDir.
Result runBinary(const std::vector<std::string>& args, const fs::path& logDir) {
    const std::string outPath = (logDir / "stdout").string(), errPath = (logDir / "stderr").string();
    std::vector<std::string> all{VDBSPLAT_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    Result r;
    if (spawned != 0) {
        r.err = "posix_spawn failed";
        return r;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(outPath);
    r.err = slurp(errPath);
    return r;
}

/// Calls fn(0 … n−1) on a few threads (the processes they start do the work).
void parallelFor(size_t n, const std::function<void(size_t)>& fn) {
    const size_t workers = std::min<size_t>(n, std::clamp<size_t>(std::thread::hardware_concurrency(), 2, 4));
    std::atomic<size_t> next{0};
    std::vector<std::thread> pool;
    for (size_t w = 0; w < workers; ++w)
        pool.emplace_back([&] {
            for (size_t i; (i = next++) < n;) fn(i);
        });
    for (auto& t : pool) t.join();
}

std::vector<std::string> listDir(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

bool contains(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

/// One bad input: run in each of @p modes ("" = no --mode from the loop).
struct BadCase {
    std::string input;               ///< the .vdb argument
    std::vector<std::string> flags;  ///< appended after the defaults
    std::string needle;              ///< the file or flag the error line must name
    std::vector<std::string> modes = kAllModes;
    bool parsing = false;  ///< rejected by the flag parser, whatever the mode: one mode suffices
};

constexpr bool kParsing = true;

/// The input files, made once for the whole suite.
class CliRender : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        char tmpl[] = "/tmp/vdbsplat_cli_render_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        shared_ = tmpl;
        fs::create_directories(shared_ / "log");
        initOpenVdb();
        GenerateOptions sphere;  // what `vdbsplat generate sphere --res 16` writes, without a process
        sphere.kind = "sphere";
        sphere.res = 16;
        writeVolume(vdb("sphere.vdb"), generateVolume(sphere));
        const std::string bytes = slurp(vdb("sphere.vdb"));
        ASSERT_GT(bytes.size(), 1000u);
        spit(vdb("half.vdb"), bytes.substr(0, bytes.size() / 2));  // truncated
        std::string junk(3000, '\0');
        for (size_t i = 0; i < junk.size(); ++i) junk[i] = char((i * 2654435761u) >> 13);
        spit(vdb("junk.vdb"), junk);  // not a VDB

        auto ints = openvdb::Int32Grid::create();
        ints->setName("labels");
        ints->tree().setValueOn(openvdb::Coord(1, 2, 3), 4);
        auto vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1, 0, 0));
        openvdb::io::File(vdb("nofloat.vdb")).write({ints, vel});
        auto empty = openvdb::FloatGrid::create(0.0f);
        empty->setName("density");
        openvdb::io::File(vdb("empty.vdb")).write({empty});

        // Tables: a pristine copy, one payload byte flipped, another kernel in the header.
        const fs::path shipped = fs::path(VDBSPLAT_SOURCE_DIR) / "tables";
        const std::string fp = slurp(shipped / "footprint.table"), ri = slurp(shipped / "reindex.table");
        ASSERT_FALSE(fp.empty());
        ASSERT_FALSE(ri.empty());
        for (const char* d : {"t_copy", "t_empty", "t_flip", "t_kernel", "t_rflip"}) fs::create_directories(shared_ / d);
        spit(shared_ / "t_copy" / "footprint.table", fp);
        spit(shared_ / "t_copy" / "reindex.table", ri);
        spit(shared_ / "t_flip" / "footprint.table", flipPayloadByte(fp));
        spit(shared_ / "t_rflip" / "reindex.table", flipPayloadByte(ri));
        // The checksum covers the payload only, so this header edit is caught by the
        // kernel identity check, not by the checksum.
        std::string k = fp;
        for (const auto& [from, to] : {std::pair<std::string, std::string>("kernel gaussian-s0.65-R2.0\n", "kernel gaussian-s0.50-R2.0\n"),
                                       std::pair<std::string, std::string>("sigma 0.65\n", "sigma 0.5\n")}) {
            const size_t at = k.find(from);
            ASSERT_NE(at, std::string::npos) << "tables/footprint.table header changed: " << from;
            ASSERT_LT(at, k.find("end_header\n"));
            k.replace(at, from.size(), to);
        }
        spit(shared_ / "t_kernel" / "footprint.table", k);
    }
    static void TearDownTestSuite() {
        std::error_code ec;
        fs::remove_all(shared_, ec);
    }
    static std::string flipPayloadByte(std::string bytes) {
        const size_t payload = bytes.find("end_header\n") + std::string("end_header\n").size();
        EXPECT_LT(payload + 1000, bytes.size());
        bytes[payload + 1000] = char(bytes[payload + 1000] ^ 0x10);
        return bytes;
    }
    static std::string vdb(const std::string& name) { return (shared_ / name).string(); }
    static std::string tables(const std::string& name) { return (shared_ / name).string(); }

    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = shared_ / info->name();
        fs::create_directories(dir_);
    }

    /// A fresh, empty output folder and log folder for one run.
    fs::path runDir(const std::string& name) const {
        const fs::path d = dir_ / name;
        fs::create_directories(d / "out");
        fs::create_directories(d / "log");
        return d;
    }

    /// `render INPUT -o OUT --size 16x16 --spp 1 [--mode MODE] FLAGS…` (defaults left out when FLAGS has them).
    static std::vector<std::string> renderArgs(const std::string& input, const std::string& output,
                                               const std::string& mode, const std::vector<std::string>& flags) {
        std::vector<std::string> a{"render", input, "-o", output};
        if (!contains(flags, "--size")) a.insert(a.end(), {"--size", "16x16"});
        if (!contains(flags, "--spp")) a.insert(a.end(), {"--spp", "1"});
        if (!mode.empty()) a.insert(a.end(), {"--mode", mode});
        a.insert(a.end(), flags.begin(), flags.end());
        return a;
    }

    /// Runs every case in every one of its modes and checks each failure.
    void expectAllFail(const std::vector<BadCase>& cases) {
        struct Run {
            size_t c;
            std::string mode;
            std::vector<std::string> args;
            fs::path out, outDir;
            Result r;
        };
        std::vector<Run> runs;
        const bool allModes = std::getenv("VDBSPLAT_TEST_ALL_MODES") != nullptr;
        for (size_t c = 0; c < cases.size(); ++c) {
            std::vector<std::string> modes = cases[c].modes;
            if (cases[c].parsing && !allModes && modes.size() > 1) modes = {modes[(rotation_++) % modes.size()]};
            for (const std::string& mode : modes) {
                const fs::path d = runDir("c" + std::to_string(c) + "_" + (mode.empty() ? "nomode" : mode));
                // Alternate the output format so both writers' paths are covered.
                const fs::path out = d / "out" / (runs.size() % 2 ? "image.exr" : "image.png");
                runs.push_back({c, mode, renderArgs(cases[c].input, out.string(), mode, cases[c].flags), out, d / "out", {}});
            }
        }
        parallelFor(runs.size(), [&](size_t i) { runs[i].r = runBinary(runs[i].args, runs[i].outDir.parent_path() / "log"); });
        const bool print = std::getenv("VDBSPLAT_PRINT_ERRORS") != nullptr;
        for (const Run& run : runs) {
            std::string cmd;
            for (size_t k = 1; k < run.args.size(); ++k) cmd += " " + run.args[k];
            SCOPED_TRACE("render" + cmd);
            const std::string& err = run.r.err;
            EXPECT_EQ(run.r.rc, 1);
            EXPECT_EQ(err.rfind("vdbsplat: error: ", 0), 0u) << err;
            EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
            EXPECT_TRUE(!err.empty() && err.back() == '\n') << err;
            EXPECT_NE(err.find(cases[run.c].needle), std::string::npos) << "expected '" << cases[run.c].needle << "' in: " << err;
            EXPECT_TRUE(run.r.out.empty()) << run.r.out;
            EXPECT_FALSE(fs::exists(run.out));
            EXPECT_TRUE(listDir(run.outDir).empty()) << "left behind: " << listDir(run.outDir).front();
            if (print) std::cout << "[" << (run.mode.empty() ? "-" : run.mode) << "]" << cmd << "\n    " << err;
        }
    }

    static fs::path shared_;
    static size_t rotation_;
    fs::path dir_;
};

fs::path CliRender::shared_;
size_t CliRender::rotation_ = 0;

TEST_F(CliRender, HelpDocumentsTablesAndExitsZero) {
    const Result r = runBinary({"render", "--help"}, runDir("help") / "log");
    EXPECT_EQ(r.rc, 0);
    EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_NE(r.out.find("usage: vdbsplat render"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--tables DIR"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("hybrid (default) | splat | point | ewa | swan | none | reference"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--kernel K"), std::string::npos) << r.out;
}

TEST_F(CliRender, BadVolumeInputs) {
    const std::string missing = vdb("missing.vdb");
    expectAllFail({
        {missing, {}, missing + ": no such file"},
        {vdb("junk.vdb"), {}, vdb("junk.vdb") + ": not a VDB file"},
        {vdb("half.vdb"), {}, vdb("half.vdb") + ": truncated or corrupt"},
        {vdb("nofloat.vdb"), {}, vdb("nofloat.vdb")},
        {vdb("sphere.vdb"), {"--grid", "temperature"}, vdb("sphere.vdb") + ": no grid named 'temperature'"},
        {vdb("empty.vdb"), {}, vdb("empty.vdb")},
    });
}

TEST_F(CliRender, BadFlagValues) {
    const std::string s = vdb("sphere.vdb");
    expectAllFail({
        {s, {"--mode", "bogus"}, "--mode: unknown mode 'bogus' (choose hybrid, splat, point, ewa, swan, none, reference)", {""}},
        {s, {"--kernel", "bspline"}, "--kernel: unknown kernel 'bspline' (choose gaussian, gaussian-sharp)", kAllModes, kParsing},
        {s, {"--tf", "no-such-preset"}, "--tf"},
        {s, {"--size", "4OOx400"}, "--size", kAllModes, kParsing},
        {s, {"--size", "0x0"}, "--size", kAllModes, kParsing},
        {s, {"--size", "100000x100000"}, "--size", kAllModes, kParsing},
        {s, {"--fov", "abc"}, "--fov", kAllModes, kParsing},
        {s, {"--fov", "0"}, "--fov", kAllModes, kParsing},
        {s, {"--fov", "180"}, "--fov", kAllModes, kParsing},
        {s, {"--spp", "1.5"}, "--spp", kAllModes, kParsing},
        {s, {"--threshold", "x"}, "--threshold", kAllModes, kParsing},
        {s, {"--threshold", "0"}, "--threshold", kAllModes, kParsing},
        {s, {"--threshold", "-1"}, "--threshold", kAllModes, kParsing},
        {s, {"--footprint", "bogus"}, "--footprint", kAllModes, kParsing},
        {s, {"--warmup", "101"}, "--warmup: expected an integer in [0, 100], got '101'", kAllModes, kParsing},
        {s, {"--warmup", "-1"}, "--warmup", kAllModes, kParsing},
        {s, {"--warmup", "two"}, "--warmup", kAllModes, kParsing},
        {s, {"--stats", (shared_ / "no" / "such" / "s.json").string()}, "--stats", kAllModes, kParsing},
        {s, {"--tables", tables("t_nowhere")}, "--tables: " + tables("t_nowhere") + ": no such directory", kAllModes, kParsing},
        {s, {"--tables", s}, "--tables: " + s + ": not a directory", kAllModes, kParsing},
    });
}

// Every shading value: NaN, negative, out of range, malformed, or a lighting flag without --shading.
TEST_F(CliRender, BadShadingFlags) {
    const std::string s = vdb("sphere.vdb");
    expectAllFail({
        {s, {"--shading", "gouraud"}, "--shading: expected 'off', 'phong' or 'ct', got 'gouraud'", kAllModes, kParsing},
        {s, {"--shading", "phong", "--ambient", "nan"}, "--ambient", kAllModes, kParsing},
        {s, {"--shading", "phong", "--ambient", "-0.1"}, "--ambient: must be a number in [0, 1]", kAllModes, kParsing},
        {s, {"--shading", "phong", "--diffuse", "1.5"}, "--diffuse: must be a number in [0, 1]", kAllModes, kParsing},
        {s, {"--shading", "ct", "--specular", "x"}, "--specular", kAllModes, kParsing},
        {s, {"--shading", "phong", "--shininess", "0"}, "--shininess: must be a number in [1, 1000]", kAllModes, kParsing},
        {s, {"--shading", "phong", "--shininess", "1e40"}, "--shininess", kAllModes, kParsing},
        {s, {"--shading", "phong", "--light", "0,0,0"}, "--light: must be a non-zero direction", kAllModes, kParsing},
        {s, {"--shading", "phong", "--light", "1,2"}, "--light", kAllModes, kParsing},
        {s, {"--shading", "phong", "--light", "inf,0,1"}, "--light", kAllModes, kParsing},
        {s, {"--ambient", "0.5"}, "--ambient: needs --shading phong or ct", kAllModes, kParsing},
        {s, {"--shading", "off", "--light", "0,0,1"}, "--light: needs --shading phong or ct", kAllModes, kParsing},
        {s, {"--gradient-opacity", "-1"}, "--gradient-opacity: must be a number in [0, 1e6]", kAllModes, kParsing},
        {s, {"--gradient-opacity", "1e300"}, "--gradient-opacity", kAllModes, kParsing},
    });
}

// --emission (docs/emission.md): a missing grid, a non-scalar grid, a grid of another voxel size
// or offset, bad map values, and map flags without --emission; then a good emission render.
TEST_F(CliRender, BadEmissionGridsAndFlags) {
    const std::string e = vdb("emission.vdb");
    if (!fs::exists(e)) {
        GenerateOptions sphere;
        sphere.kind = "sphere";
        sphere.res = 16;
        auto density = generateVolume(sphere);
        auto hot = density->deepCopy();
        hot->setName("temperature");
        auto coarse = density->deepCopy();
        coarse->setName("coarse");
        coarse->setTransform(openvdb::math::Transform::createLinearTransform(2.0));
        auto shifted = density->deepCopy();
        shifted->setName("shifted");
        shifted->transform().postTranslate(openvdb::Vec3d(0.0, 0.0, 0.5));
        auto vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1, 0, 0));
        openvdb::io::File(e).write({density, hot, coarse, shifted, vel});
    }
    expectAllFail({
        {e, {"--grid", "density", "--emission", "nosuch"}, e + ": no grid named 'nosuch'"},
        {e, {"--grid", "density", "--emission", "vel"}, e + ": grid 'vel' holds vec3s values"},
        {e, {"--grid", "density", "--emission", "coarse"}, e + ": emission grid 'coarse' has another transform than density grid 'density'"},
        {e, {"--grid", "density", "--emission", "shifted"}, e + ": emission grid 'shifted' has another transform"},
        {e, {"--grid", "density", "--emission", "density"}, e + ": --emission grid 'density' is the density grid"},
        {e, {"--grid", "density", "--emission", "temperature", "--emission-map", "nosuch"}, "--emission-map"},
        {e, {"--grid", "density", "--emission", "temperature", "--emission-scale", "-1"}, "--emission-scale", kAllModes, kParsing},
        {e, {"--grid", "density", "--emission", "temperature", "--kelvin", "5000,100"}, "--kelvin", kAllModes, kParsing},
        {e, {"--grid", "density", "--emission", "temperature", "--kelvin", "5000"}, "--kelvin", kAllModes, kParsing},
        {e, {"--grid", "density", "--emission-scale", "2"}, "--emission-scale: needs --emission GRID", kAllModes, kParsing},
        {e, {"--grid", "density", "--emission", ""}, "--emission: expected a grid name", kAllModes, kParsing},
    });
    const fs::path d = runDir("emission_good");
    const fs::path out = d / "out" / "fire.png";
    const Result r = runBinary(renderArgs(e, out.string(), "hybrid", {"--grid", "density", "--emission", "temperature"}), d / "log");
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(fs::exists(out));
}

TEST_F(CliRender, BadCameras) {
    const std::string s = vdb("sphere.vdb");
    expectAllFail({
        {s, {"--eye", "1,2"}, "--eye", kAllModes, kParsing},
        {s, {"--eye", "nan,0,0"}, "--eye", kAllModes, kParsing},
        {s, {"--eye", "inf,0,0"}, "--eye", kAllModes, kParsing},
        {s, {"--eye", "1e300,0,0"}, "--eye"},
        {s, {"--eye", "1,2,3", "--look-at", "1,2,3"}, "--eye: equals --look-at"},
        {s, {"--eye", "7.5,7.5,7.5"}, "--eye: equals --look-at"},  // the default look-at: the grid's centre
        {s, {"--eye", "7.5,7.5,40", "--look-at", "7.5,7.5,0", "--up", "0,0,1"}, "--up: parallel"},
    });
}

TEST_F(CliRender, BadTablesNameTheTableFile) {
    const std::string s = vdb("sphere.vdb");
    const std::string flip = tables("t_flip"), kernel = tables("t_kernel"), rflip = tables("t_rflip");
    expectAllFail({
        {s, {"--tables", flip}, flip + "/footprint.table: checksum mismatch", kForwardModes},
        {s, {"--tables", kernel}, kernel + "/footprint.table: table built for kernel 'gaussian-s0.50-R2.0'", kForwardModes},
        {s, {"--tables", rflip}, rflip + "/reindex.table: checksum mismatch", kForwardModes},
    });
}

TEST_F(CliRender, FailedRenderDoesNotClobberAnExistingImage) {
    const std::string s = vdb("sphere.vdb");
    const std::string keep = "not an image: these bytes must survive a failed render\n";
    struct Run {
        std::vector<std::string> args;
        fs::path out;
        Result r;
    };
    std::vector<Run> runs;
    struct Failure {
        std::string input;
        std::vector<std::string> flags;
        std::vector<std::string> modes;  // two each, all four covered
    };
    const std::string missing = vdb("missing.vdb");
    const std::vector<Failure> failures = {
        {s, {"--fov", "abc"}, {"hybrid", "reference"}},                                         // flag parsing
        {missing, {}, {"splat", "point"}},                                                      // loading
        {s, {"--stats", (shared_ / "no" / "dir" / "s.json").string()}, {"point", "reference"}},  // output checks
        {s, {"--eye", "1,2,3", "--look-at", "1,2,3"}, {"hybrid", "splat"}},                     // camera, after loading
        {s, {"--tables", tables("t_flip")}, {"hybrid", "point"}},                               // inside render()
    };
    for (size_t f = 0; f < failures.size(); ++f)
        for (size_t m = 0; m < failures[f].modes.size(); ++m) {
            const std::string& mode = failures[f].modes[m];
            const fs::path d = runDir(mode + std::to_string(f));
            const fs::path out = d / "out" / ((f + m) % 2 ? "out.exr" : "out.png");
            spit(out, keep);
            runs.push_back({renderArgs(failures[f].input, out.string(), mode, failures[f].flags), out, {}});
        }
    parallelFor(runs.size(), [&](size_t i) { runs[i].r = runBinary(runs[i].args, runs[i].out.parent_path().parent_path() / "log"); });
    for (const Run& run : runs) {
        std::string cmd;
        for (const std::string& a : run.args) cmd += " " + a;
        SCOPED_TRACE(cmd);
        EXPECT_EQ(run.r.rc, 1) << run.r.err;
        EXPECT_EQ(slurp(run.out), keep);
        EXPECT_EQ(listDir(run.out.parent_path()), std::vector<std::string>{run.out.filename().string()});
    }
}

TEST_F(CliRender, GoodRenderInEachModeToPngAndExr) {
    struct Run {
        std::string mode;
        std::vector<std::string> args;
        fs::path out;
        Result r;
    };
    std::vector<Run> runs;
    for (const std::string& mode : kAllModes)
        for (const char* ext : {".png", ".exr"}) {
            const fs::path d = runDir(mode + ext);
            const fs::path out = d / "out" / (std::string("img") + ext);
            runs.push_back({mode, renderArgs(vdb("sphere.vdb"), out.string(), mode, {"--size", "24x20"}), out, {}});
        }
    parallelFor(runs.size(), [&](size_t i) { runs[i].r = runBinary(runs[i].args, runs[i].out.parent_path().parent_path() / "log"); });
    for (const Run& run : runs) {
        SCOPED_TRACE(run.mode + " " + run.out.filename().string());
        ASSERT_EQ(run.r.rc, 0) << run.r.err;
        EXPECT_TRUE(run.r.err.empty()) << run.r.err;
        ASSERT_TRUE(fs::exists(run.out));
        EXPECT_EQ(listDir(run.out.parent_path()), std::vector<std::string>{run.out.filename().string()});  // no temporary
        const Image img = readImage(run.out.string());
        EXPECT_EQ(img.width, 24);
        EXPECT_EQ(img.height, 20);
        float peak = 0.0f;
        for (const glm::vec4& p : img.pixels) peak = std::max(peak, p.x);
        EXPECT_GT(peak, 0.05f) << "the sphere is in the picture";
        const glm::vec4 corner = img.pixels.front();
        EXPECT_LT(std::max({corner.x, corner.y, corner.z}), 1e-3f) << "the corner is empty";
    }
}

// The study modes and the kernel are echoed with what they used: ewa and swan low-pass each
// primitive (prefilter), none nothing (and no level of detail); swan and none draw no points
// under the threshold... except none, whose minified voxels are nearest-pixel points.
TEST_F(CliRender, StatsJsonEchoesStudyModesAndKernel) {
    const fs::path d = runDir("stats-modes");
    struct Expect { const char* mode; const char* order; double lod; bool points; };
    for (const Expect e : {Expect{"ewa", "prefilter", 1.25, false}, Expect{"swan", "prefilter", 1.25, false},
                           Expect{"none", "none", 0.0, true}}) {
        const fs::path stats = d / "out" / (std::string(e.mode) + ".json");
        const Result r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "out" / (std::string(e.mode) + ".png")).string(),
                                              e.mode, {"--size", "32x32", "--kernel", "gaussian-sharp", "--stats", stats.string()}),
                                   d / "log");
        ASSERT_EQ(r.rc, 0) << r.err;
        const nlohmann::json j = nlohmann::json::parse(slurp(stats));
        EXPECT_EQ(j["mode"], e.mode);
        EXPECT_EQ(j["kernel"], "gaussian-sharp");
        EXPECT_EQ(j["filter_order"], e.order) << e.mode;
        EXPECT_EQ(j["subpixels"], 1) << e.mode;
        EXPECT_EQ(j["lod"].get<double>(), e.lod) << e.mode;
        EXPECT_GT(j["splats"].get<double>(), 0.0) << e.mode;
        EXPECT_EQ(j["points"].get<double>() > 0.0, e.points) << e.mode;
    }
}

// --subpixels auto (the default) echoes the k it used for the view: 2 for a shaded view of
// points only, 1 unshaded or where voxels are splats; an explicit k as given.
TEST_F(CliRender, StatsJsonEchoesTheSubpixelsUsed) {
    const fs::path d = runDir("stats-subpixels");
    struct Expect { const char* name; std::vector<std::string> flags; int k; };
    for (const Expect& e : {Expect{"far-shaded", {"--shading", "phong", "--distance", "8"}, 2},
                            Expect{"far", {"--distance", "8"}, 1},
                            Expect{"close-shaded", {"--shading", "phong", "--distance", "0.35"}, 1},
                            Expect{"far-shaded-1", {"--shading", "phong", "--distance", "8", "--subpixels", "1"}, 1},
                            Expect{"far-auto-3", {"--distance", "8", "--subpixels", "auto", "--subpixels", "3"}, -1}}) {
        const fs::path stats = d / "out" / (std::string(e.name) + ".json");
        std::vector<std::string> flags = e.flags;
        flags.insert(flags.end(), {"--size", "48x48", "--stats", stats.string()});
        const Result r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "out" / (std::string(e.name) + ".png")).string(),
                                              "hybrid", flags),
                                   d / "log");
        if (e.k < 0) {  // given twice
            EXPECT_EQ(r.rc, 1) << e.name;
            continue;
        }
        ASSERT_EQ(r.rc, 0) << e.name << ": " << r.err;
        EXPECT_EQ(nlohmann::json::parse(slurp(stats))["subpixels"], e.k) << e.name;
    }
}

// --lod-blend auto is Still for a still image; the rule used is echoed, and every value parses.
TEST_F(CliRender, StatsJsonEchoesTheLevelBlend) {
    const fs::path d = runDir("stats-lod-blend");
    for (const auto& [given, used] : std::vector<std::pair<std::string, std::string>>{
             {"", "still"}, {"auto", "still"}, {"on", "on"}, {"off", "off"}, {"still", "still"}}) {
        const std::string name = given.empty() ? "default" : given;
        const fs::path stats = d / "out" / (name + ".json");
        std::vector<std::string> flags = {"--distance", "8", "--size", "48x48", "--stats", stats.string()};
        if (!given.empty()) flags.insert(flags.end(), {"--lod-blend", given});
        const Result r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "out" / (name + ".png")).string(), "hybrid", flags),
                                   d / "log");
        ASSERT_EQ(r.rc, 0) << name << ": " << r.err;
        EXPECT_EQ(nlohmann::json::parse(slurp(stats))["lod_blend"], used) << name;
    }
}

TEST_F(CliRender, StatsJsonHasCountsTimingsAndSettings) {
    const fs::path d = runDir("stats");
    const fs::path stats = d / "out" / "s.json";
    const Result r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "out" / "img.png").string(), "hybrid",
                                          {"--size", "32x32", "--stats", stats.string(), "-v"}),
                               d / "log");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("hybrid 32x32"), std::string::npos) << r.out;
    const nlohmann::json j = nlohmann::json::parse(slurp(stats));
    for (const char* key : {"seconds", "width", "height", "active_voxels", "mode", "points", "splats", "culled",
                            "splat_fraction", "stage_seconds", "tables", "camera", "input", "grid", "page_faults"})
        EXPECT_TRUE(j.contains(key)) << key << " in " << j.dump();
    EXPECT_EQ(j["mode"], "hybrid");
    EXPECT_EQ(j["width"], 32);
    EXPECT_EQ(j["height"], 32);
    EXPECT_EQ(j["grid"], "density");
    EXPECT_EQ(j["tables"], "");
    EXPECT_EQ(j["footprint"], "auto") << "the default footprint path";
    EXPECT_EQ(j["kernel"], "gaussian") << "the default kernel";
    EXPECT_GE(j["splats_exact_index"].get<double>(), 0.0);
    EXPECT_LE(j["splats_exact_index"].get<double>(), j["splats"].get<double>());
    EXPECT_GT(j["active_voxels"].get<double>(), 1000.0);
    EXPECT_GE(j["seconds"].get<double>(), 0.0);
    EXPECT_GT(j["points"].get<double>(), 0.0);  // this view has both kinds
    EXPECT_GT(j["splats"].get<double>(), 0.0);
    EXPECT_GE(j["culled"].get<double>(), 0.0);
    const double drawn = j["points"].get<double>() + j["splats"].get<double>();
    EXPECT_NEAR(j["splat_fraction"].get<double>(), j["splats"].get<double>() / drawn, 1e-12);
    for (const char* stage : {"stream", "project", "rasterize", "composite"}) {
        ASSERT_TRUE(j["stage_seconds"].contains(stage)) << stage;
        EXPECT_GE(j["stage_seconds"][stage].get<double>(), 0.0) << stage;
    }
    EXPECT_EQ(listDir(d / "out"), (std::vector<std::string>{"img.png", "s.json"}));
}

TEST_F(CliRender, StatsJsonRecordsTheFramingAndTheRaysUsed) {
    const fs::path d = runDir("stats-framing");
    const fs::path stats = d / "s.json";
    Result r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "a.png").string(), "hybrid",
                                    {"--size", "16x16", "--view-dir", "1,0,0", "--up", "0,0,1", "--stats",
                                     stats.string()}),
                         d / "log");
    ASSERT_EQ(r.rc, 0) << r.err;
    nlohmann::json j = nlohmann::json::parse(slurp(stats));
    ASSERT_TRUE(j.contains("view_dir")) << j.dump();
    EXPECT_EQ(j["view_dir"], nlohmann::json({1.0, 0.0, 0.0}));
    EXPECT_EQ(j["up"], nlohmann::json({0.0, 0.0, 1.0}));
    EXPECT_FALSE(j.contains("rays_per_pixel")) << "forward modes trace no rays";

    r = runBinary(renderArgs(vdb("sphere.vdb"), (d / "b.png").string(), "reference",
                             {"--size", "8x8", "--spp", "5", "--stats", stats.string()}),
                  d / "log");
    ASSERT_EQ(r.rc, 0) << r.err;
    j = nlohmann::json::parse(slurp(stats));
    EXPECT_EQ(j["spp"], 5) << "the setting as given";
    EXPECT_EQ(j["rays_per_pixel"], 9) << "rounded up to a square: 3x3 strata";
    EXPECT_FALSE(j.contains("view_dir"));
}

TEST_F(CliRender, ImageIndependentOfThreadsAndOfTablesSource) {
    // 32x32 hybrid: a mix of points and splats (checked in StatsJsonHasCountsTimingsAndSettings).
    const std::vector<std::pair<std::string, std::vector<std::string>>> variants = {
        {"t2", {"--threads", "2"}},
        {"t1", {"--threads", "1"}},
        {"t2copy", {"--threads", "2", "--tables", tables("t_copy")}},    // a copy of the shipped tables
        {"t1built", {"--threads", "1", "--tables", tables("t_empty")}},  // no files: built in memory
    };
    std::vector<fs::path> outs;
    std::vector<Result> results(variants.size());
    std::vector<std::vector<std::string>> args;
    for (const auto& [name, flags] : variants) {
        const fs::path d = runDir(name);
        outs.push_back(d / "out" / "img.png");
        std::vector<std::string> f = flags;
        f.insert(f.end(), {"--size", "32x32"});
        args.push_back(renderArgs(vdb("sphere.vdb"), outs.back().string(), "hybrid", f));
    }
    parallelFor(variants.size(), [&](size_t i) { results[i] = runBinary(args[i], outs[i].parent_path().parent_path() / "log"); });
    for (size_t i = 0; i < variants.size(); ++i) ASSERT_EQ(results[i].rc, 0) << variants[i].first << ": " << results[i].err;
    const std::string first = slurp(outs[0]);
    ASSERT_GT(first.size(), 100u);
    for (size_t i = 1; i < variants.size(); ++i) EXPECT_TRUE(slurp(outs[i]) == first) << variants[i].first << " differs";
}

// --warmup N renders the view N times first with buffers (and level-of-detail moments) kept, as
// bench and animate do, and times the last render: the image is the cold render's, bit for bit,
// and the stats say how many renders came before. A far view, so the kept moments are read back.
TEST_F(CliRender, WarmRenderEqualsTheColdOneAndSaysSo) {
    const std::vector<std::pair<std::string, std::vector<std::string>>> variants = {
        {"cold", {}}, {"warm", {"--warmup", "2"}}};
    std::vector<fs::path> outs, stats;
    std::vector<std::vector<std::string>> args;
    for (const auto& [name, flags] : variants) {
        const fs::path d = runDir(name);
        outs.push_back(d / "out" / "img.exr"), stats.push_back(d / "out" / "s.json");
        std::vector<std::string> f = flags;
        f.insert(f.end(), {"--size", "48x48", "--distance", "6", "--stats", stats.back().string()});
        args.push_back(renderArgs(vdb("sphere.vdb"), outs.back().string(), "hybrid", f));
    }
    std::vector<Result> results(variants.size());
    parallelFor(variants.size(), [&](size_t i) { results[i] = runBinary(args[i], outs[i].parent_path().parent_path() / "log"); });
    for (size_t i = 0; i < variants.size(); ++i) ASSERT_EQ(results[i].rc, 0) << variants[i].first << ": " << results[i].err;
    const Image cold = readImage(outs[0].string()), warm = readImage(outs[1].string());
    ASSERT_EQ(cold.pixels.size(), warm.pixels.size());
    EXPECT_TRUE(std::equal(cold.pixels.begin(), cold.pixels.end(), warm.pixels.begin())) << "the warm render differs";
    const nlohmann::json c = nlohmann::json::parse(slurp(stats[0])), w = nlohmann::json::parse(slurp(stats[1]));
    EXPECT_EQ(c["warmup"], 0);
    EXPECT_EQ(w["warmup"], 2);
    EXPECT_GT(w["lod_aggregates"].get<double>(), 0.0) << "a far view: the kept moments are used";
    EXPECT_EQ(w["points"], c["points"]);
    EXPECT_EQ(w["culled"], c["culled"]);
}

}  // namespace
}  // namespace vdbsplat

namespace vdbsplat {
namespace {

/// Starts a reference render long enough to be interrupted (-v: progress lines on stderr,
/// which is a file here), waits for its first progress line, sends @p sig, and checks the
/// contract: exit 1, the error as the last stderr line, no image and no temporary left.
void interruptRender(const std::string& input, const fs::path& dir, int sig, bool verbose) {
    const std::string image = (dir / "out.png").string(), outPath = (dir / "o.txt").string(),
                      errPath = (dir / "e.txt").string();
    std::vector<std::string> args{"render", input, "-o", image, "--mode", "reference", "--spp", "1024",
                                  "--size", "200x200", "--threads", "1"};
    if (verbose) args.push_back("-v");
    const pid_t pid = test::spawnVdbsplat(args, outPath, errPath);
    ASSERT_GT(pid, 0);
    if (verbose) {  // the progress line proves -v reports while rendering, and that it has begun
        for (int i = 0; i < 2400 && slurp(errPath).find("reference:  10%") == std::string::npos; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    EXPECT_TRUE(test::waitForHandler(pid, sig, 60));  // the guard is installed before the grid loads
    ::kill(pid, sig);
    const int status = test::waitBounded(pid, 60);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 1);
    const std::string err = slurp(errPath);
    const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
    const std::string last = "vdbsplat: error: render interrupted by " + name + "; " + image + " not written\n";
    ASSERT_GE(err.size(), last.size()) << err;
    EXPECT_EQ(err.substr(err.size() - last.size()), last) << err;
    if (verbose) {
        EXPECT_NE(err.find("reference:  10%  ETA "), std::string::npos) << err;
        EXPECT_EQ(err.find("100%"), std::string::npos) << err;  // it did not finish
    } else {
        EXPECT_EQ(err, last);  // one line
    }
    EXPECT_TRUE(slurp(outPath).empty());
    EXPECT_FALSE(fs::exists(image));
    test::expectNoTemporaries(dir);
}

TEST_F(CliRender, CtrlCStopsALongRenderAndWritesNothing) {
    interruptRender(vdb("sphere.vdb"), runDir("int"), SIGINT, false);
}

TEST_F(CliRender, VerboseShowsProgressAndSigtermStopsIt) {
    interruptRender(vdb("sphere.vdb"), runDir("term"), SIGTERM, true);
}

TEST_F(CliRender, VerboseProgressEndsAtOneHundredPercent) {
    const fs::path d = runDir("v");
    const test::CliResult r = test::runVdbsplat(
        "render '" + vdb("sphere.vdb") + "' -o '" + (d / "out" / "a.png").string() + "' --size 32x32 -v", d / "log");
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("hybrid: 100%  done in "), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("hybrid 32x32"), std::string::npos) << r.out;  // the one-line statistics
}

}  // namespace
}  // namespace vdbsplat
