// tests/cli/test_cli_animate.cpp — `vdbsplat animate` run as the real binary, on a tiny
// generated sphere (16³ voxels) at 48×48 or smaller, a few frames each: the zoom's frames and
// frames.csv, --resume (keeps finished frames, re-renders a deleted one), refusal of a
// non-empty folder, orbit and keyframe paths, --reference's PSNR/flicker columns and plot,
// --force, the --mp4 note, Ctrl-C between frames, and bad input: one line, exit 1, no output.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#include <nlohmann/json.hpp>

#include "image/image.h"
#include "support/cli.h"

extern char** environ;

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::slurp;
using test::spit;

using test::fields;
using test::lines;

size_t countFiles(const fs::path& dir, const std::string& prefix) {
    size_t n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
    return n;
}

class AnimateCli : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        scratch_ = new test::ScratchDir("animate");
        const CliResult r = test::runVdbsplat("generate sphere --res 16 -o '" + vdb() + "'", scratch_->dir());
        ASSERT_EQ(r.rc, 0) << r.err;
    }
    static void TearDownTestSuite() {
        delete scratch_;
        scratch_ = nullptr;
    }
    static std::string vdb() { return scratch_->path("sphere.vdb"); }
    CliResult animate(const std::string& args) const {
        return test::runVdbsplat("animate '" + vdb() + "' " + args, local_.dir());
    }
    std::string out(const std::string& name) const { return local_.path(name); }

    static test::ScratchDir* scratch_;
    test::ScratchDir local_{"animate-run"};
};
test::ScratchDir* AnimateCli::scratch_ = nullptr;

TEST_F(AnimateCli, ZoomWritesFramesAndCsv) {
    const std::string dir = out("zoom");
    const CliResult r = animate("-o '" + dir + "' --from 4 --to 1 --frames 4 --size 48x48 --threads 1");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;  // no progress bar when stderr is not a terminal
    EXPECT_NE(r.out.find("4 frames (4 rendered, 0 kept)"), std::string::npos) << r.out;
    for (int i = 0; i < 4; ++i) {
        const std::string f = dir + "/frame_000" + std::to_string(i) + ".png";
        ASSERT_TRUE(fs::exists(f)) << f;
        const Image im = readImage(f);
        EXPECT_EQ(im.width, 48);
        EXPECT_EQ(im.height, 48);
    }
    EXPECT_FALSE(fs::exists(dir + "/frame_0004.png"));
    test::expectNoTemporaries(dir);
    const auto csv = lines(slurp(dir + "/frames.csv"));
    ASSERT_EQ(csv.size(), 5u);
    EXPECT_EQ(csv[0], "frame,time,distance,eye_x,eye_y,eye_z,fov,seconds,points,splats,splat_fraction,switch");
    const double expected[] = {4.0, 4.0 * std::pow(0.25, 1.0 / 3), 4.0 * std::pow(0.25, 2.0 / 3), 1.0};
    double previousEyeDistance = 1e300;
    for (int i = 0; i < 4; ++i) {
        const auto f = fields(csv[size_t(i) + 1]);
        ASSERT_EQ(f.size(), 12u) << csv[size_t(i) + 1];
        EXPECT_EQ(f[0], std::to_string(i));
        EXPECT_NEAR(std::stod(f[2]), expected[i], 1e-6);
        const double eyeDistance = std::hypot(std::stod(f[3]) - 7.5, std::stod(f[4]) - 7.5, std::stod(f[5]) - 7.5);
        EXPECT_LT(eyeDistance, previousEyeDistance);  // zooming in
        previousEyeDistance = eyeDistance;
        EXPECT_GE(std::stod(f[7]), 0.0);
        const double points = std::stod(f[8]), splats = std::stod(f[9]), fraction = std::stod(f[10]);
        EXPECT_GT(points + splats, 0.0);
        EXPECT_NEAR(fraction, splats / (points + splats), 1e-5);
    }
    // The far frame is mostly points, the near one mostly splats.
    EXPECT_LT(std::stod(fields(csv[1])[10]), std::stod(fields(csv[4])[10]));
    EXPECT_TRUE(fs::exists(dir + "/animation.json"));
}

// --subpixels auto is fixed once for the whole path (a zoom never switches grids between two
// frames): 2 for a shaded path that stays among points, 1 for one that reaches splats or is
// unshaded (animation.json records the k every frame used).
TEST_F(AnimateCli, AutoSubpixelsAreFixedForThePath) {
    struct Case { const char* name; const char* args; int k; };
    for (const Case c : {Case{"far", "--from 8 --to 4 --shading phong", 2}, Case{"through", "--from 8 --to 1 --shading phong", 1},
                         Case{"unshaded", "--from 8 --to 4", 1}}) {
        const std::string dir = out(c.name);
        const CliResult r = animate("-o '" + dir + "' " + c.args + " --frames 3 --size 48x48");
        ASSERT_EQ(r.rc, 0) << r.err;
        const nlohmann::json record = nlohmann::json::parse(slurp(dir + "/animation.json"));
        EXPECT_EQ(record.at("settings").at("subpixels"), c.k) << c.name;
        // --lod-blend auto: a path blends every level-of-detail passage (no pop between frames).
        EXPECT_EQ(record.at("settings").at("lod_blend"), "on") << c.name;
    }
}

TEST_F(AnimateCli, ResumeKeepsFramesAndRerendersADeletedOne) {
    const std::string dir = out("resume");
    const std::string args = "-o '" + dir + "' --from 3 --to 1 --frames 4 --size 32x32 --threads 1";
    ASSERT_EQ(animate(args).rc, 0);
    const auto before = fs::last_write_time(dir + "/frame_0000.png");
    const std::string csvBefore = slurp(dir + "/frames.csv");
    fs::remove(dir + "/frame_0002.png");
    // Without --resume: refused, one line, nothing touched.
    const CliResult refused = animate(args);
    test::expectOneLineError(refused, "not empty");
    EXPECT_FALSE(fs::exists(dir + "/frame_0002.png"));
    const CliResult r = animate(args + " --resume");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("(1 rendered, 3 kept)"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(dir + "/frame_0002.png"));
    EXPECT_EQ(fs::last_write_time(dir + "/frame_0000.png"), before);
    // Rows agree except the re-rendered frame's timing.
    const auto a = lines(csvBefore), b = lines(slurp(dir + "/frames.csv"));
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
        if (i != 3) {
            EXPECT_EQ(a[i], b[i]);
        }
    // A damaged frame is not kept either, and a temporary left by a killed writer is removed.
    spit(dir + "/frame_0001.png", "not a png");
    spit(dir + "/frame_0003.png.tmp4242.png", "partial");
    const CliResult r2 = animate(args + " --resume");
    ASSERT_EQ(r2.rc, 0) << r2.err;
    EXPECT_NE(r2.out.find("(1 rendered, 3 kept)"), std::string::npos) << r2.out;
    EXPECT_EQ(readImage(dir + "/frame_0001.png").width, 32);
    EXPECT_FALSE(fs::exists(dir + "/frame_0003.png.tmp4242.png"));
    // --resume with other settings is refused.
    test::expectOneLineError(animate(args + " --resume --threshold 2"), "another animation");
    // So is a folder whose record an older build wrote: it left out --cutoff, --compositing,
    // --slab-thickness and the second --lod cap at their defaults (--cutoff's was 1e-4 then);
    // today's record holds them. Nothing is touched.
    {
        const std::string json = dir + "/animation.json";
        const std::string recordText = slurp(json);
        nlohmann::json record = nlohmann::json::parse(recordText);
        ASSERT_TRUE(record.at("settings").contains("cutoff"));
        for (const char* key : {"cutoff", "compositing", "slab_thickness", "lod_coarse"}) record["settings"].erase(key);
        spit(json, record.dump(2));
        const auto frameTime = fs::last_write_time(dir + "/frame_0000.png");
        test::expectOneLineError(animate(args + " --resume"), "older vdbsplat");
        EXPECT_EQ(fs::last_write_time(dir + "/frame_0000.png"), frameTime);
        spit(json, recordText);
        ASSERT_EQ(animate(args + " --resume").rc, 0);  // its own record back: accepted again
    }
    // --force starts afresh, and a shorter run leaves no stale frames behind.
    const CliResult f = animate("-o '" + dir + "' --from 3 --to 1 --frames 2 --size 32x32 --force");
    ASSERT_EQ(f.rc, 0) << f.err;
    EXPECT_EQ(countFiles(dir, "frame_"), 2u);
    EXPECT_EQ(lines(slurp(dir + "/frames.csv")).size(), 3u);
}

TEST_F(AnimateCli, OrbitAndKeyframes) {
    const std::string orbit = out("orbit");
    const CliResult r = animate("-o '" + orbit + "' --orbit 90 --frames 3 --size 24x24 --format exr");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(countFiles(orbit, "frame_"), 3u);
    EXPECT_TRUE(fs::exists(orbit + "/frame_0002.exr"));
    const auto csv = lines(slurp(orbit + "/frames.csv"));
    ASSERT_EQ(csv.size(), 4u);
    double r0 = -1;
    for (size_t i = 1; i < csv.size(); ++i) {
        const auto f = fields(csv[i]);
        const double rad = std::hypot(std::stod(f[3]) - 7.5, std::stod(f[4]) - 7.5, std::stod(f[5]) - 7.5);
        if (r0 < 0) r0 = rad;
        EXPECT_NEAR(rad, r0, 1e-4 * r0);
    }

    const std::string path = out("keys.json");
    spit(path, R"([{"eye":[40,0,8],"look_at":[7.5,7.5,7.5],"time":0},
                   {"eye":[0,40,8],"look_at":[7.5,7.5,7.5],"fov":40,"time":1},
                   {"eye":[-30,0,8],"look_at":[7.5,7.5,7.5],"up":[0,0,1],"time":2}])");
    const std::string keys = out("keys");
    const CliResult k = animate("-o '" + keys + "' --path '" + path + "' --fps 2 --size 24x24");
    ASSERT_EQ(k.rc, 0) << k.err;
    EXPECT_EQ(countFiles(keys, "frame_"), 5u);  // t = 0, 0.5, 1, 1.5, 2
    const auto kc = lines(slurp(keys + "/frames.csv"));
    ASSERT_EQ(kc.size(), 6u);
    EXPECT_EQ(fields(kc[3])[6], "40");     // fov of the key at t = 1
    EXPECT_EQ(fields(kc[3])[3], "0");      // through the key's eye
    EXPECT_EQ(fields(kc[3])[4], "40");
}

TEST_F(AnimateCli, ReferenceWritesPsnrFlickerAndPlot) {
    const std::string dir = out("ref");
    const CliResult r =
        animate("-o '" + dir + "' --from 2 --to 1 --frames 3 --size 24x24 --spp 1 --reference --mp4");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("mean flicker"), std::string::npos) << r.out;
    const auto csv = lines(slurp(dir + "/frames.csv"));
    ASSERT_EQ(csv.size(), 4u);
    EXPECT_EQ(csv[0], "frame,time,distance,eye_x,eye_y,eye_z,fov,seconds,points,splats,splat_fraction,switch,"
                      "psnr,flicker,reference_seconds");
    for (size_t i = 1; i < 4; ++i) {
        const auto f = fields(csv[i]);
        ASSERT_EQ(f.size(), 15u) << csv[i];
        EXPECT_GT(std::stod(f[12]), 15.0) << csv[i];  // PSNR
        if (i == 1) {
            EXPECT_EQ(f[13], "");  // no flicker for the first frame
        } else {
            EXPECT_GE(std::stod(f[13]), 0.0);
        }
        EXPECT_GT(std::stod(f[14]), 0.0);  // the reference was rendered
    }
    EXPECT_EQ(countFiles(dir + "/reference", "frame_"), 3u);
    const std::string svg = slurp(dir + "/plot.svg");
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("polyline"), std::string::npos);
    // --mp4: a video when ffmpeg is on PATH, else a note (not an error).
    if (std::system("command -v ffmpeg >/dev/null 2>&1") == 0) {
        EXPECT_TRUE(fs::exists(dir + "/animation.mp4"));
    } else {
        EXPECT_NE(r.err.find("vdbsplat: note: --mp4: ffmpeg is not on PATH"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;
    }
    // --resume reuses the cached reference frames: nothing rendered again.
    const CliResult again =
        animate("-o '" + dir + "' --from 2 --to 1 --frames 3 --size 24x24 --spp 1 --reference --resume");
    ASSERT_EQ(again.rc, 0) << again.err;
    EXPECT_NE(again.out.find("(0 rendered, 3 kept)"), std::string::npos) << again.out;
    EXPECT_EQ(lines(slurp(dir + "/frames.csv")), csv);
}

TEST_F(AnimateCli, BadInputOneLineNoOutput) {
    const std::string ok = R"("eye":[40,0,8],"look_at":[7.5,7.5,7.5])";
    const std::vector<std::pair<std::string, std::string>> files = {
        {"[]", "no keyframes"},
        {"[{" + ok + ",\"time\":1},{" + ok + ",\"time\":0.5}]", "times must increase"},
        {"[{" + ok + ",\"time\":NaN}]", "not valid JSON"},
        {"[{" + ok + "}]", "missing \"time\""},
        {"[{" + ok + ",\"time\":\"zero\"}]", "expected a number"},
        {"[{" + ok + ",\"time\":0,\"speed\":3}]", "unknown key 'speed'"},
        {std::string(5000, '[') + std::string(5000, ']'), "nested deeper"},
        {"[{\"eye\":[7.5,7.5,40],\"look_at\":[7.5,7.5,7.5],\"time\":0}]", "parallel"},  // up along the view
    };
    struct Case {
        std::string args, needle, context;
        bool namesFile = false;
        CliResult result;
    };
    std::vector<Case> cases;
    const std::string never = out("never");
    for (size_t n = 0; n < files.size(); ++n) {
        const std::string path = out("bad" + std::to_string(n) + ".json");
        spit(path, files[n].first);
        cases.push_back({"-o '" + never + "' --path '" + path + "' --frames 2 --size 16x16", files[n].second,
                         files[n].first.substr(0, 60), true, {}});
    }
    const std::vector<std::pair<std::string, std::string>> flags = {
        {"--from 4 --to 1 --frames 0", "--frames"},
        {"--from 4 --to 1 --frames 100001", "--frames"},
        {"--from 4 --to 1 --frames abc", "--frames"},
        {"--from 0 --to 1 --frames 4", "--from"},
        {"--from 4 --to -1 --frames 4", "--to"},
        {"--from 4 --frames 4", "--to"},
        {"--from 4 --to 1", "--frames"},
        {"--frames 4", "no camera path"},
        {"--from 4 --to 1 --orbit 90 --frames 4", "more than one camera path"},
        {"--orbit 90 --frames 4 --format jpg", "--format"},
        {"--orbit 90 --frames 4 --mode bogus", "unknown mode"},
        {"--orbit 90 --frames 4 --eye 1,2,3", "--eye"},
        {"--orbit 90 --frames 4 --resume --force", "--resume"},
        {"--path '/nonexistent/p.json' --frames 4", "/nonexistent/p.json"},
        {"--path '/nonexistent/p.json'", "--frames"},
    };
    for (const auto& [args, needle] : flags) cases.push_back({"-o '" + never + "' " + args, needle, args, false, {}});
    spit(out("file"), "x");
    cases.push_back({"-o '/nonexistent/x/y' --orbit 90 --frames 2", "parent folder", "parent", false, {}});
    cases.push_back({"-o '" + out("file") + "' --orbit 90 --frames 2", "not a folder", "file", false, {}});
    // Each run is a separate process (mostly start-up time): four at a time, each with its own log folder.
    std::atomic<size_t> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < 4; ++t)
        pool.emplace_back([&, t] {
            const fs::path logs = local_.dir() / ("logs" + std::to_string(t));
            fs::create_directories(logs);
            for (size_t i; (i = next++) < cases.size();)
                cases[i].result = test::runVdbsplat("animate '" + vdb() + "' " + cases[i].args, logs);
        });
    for (auto& th : pool) th.join();
    for (const Case& c : cases) {
        test::expectOneLineError(c.result, c.needle, c.context);
        if (c.namesFile) {
            EXPECT_NE(c.result.err.find(out("bad")), std::string::npos) << c.result.err;
        }
    }
    EXPECT_FALSE(fs::exists(never));
}

/// Starts animate (no shell: SIGINT and SIGTERM at their default, as in a terminal), waits for
/// its fourth frame, sends @p sig, and checks the interruption contract.
void interruptAndCheck(const std::string& vdbPath, const test::ScratchDir& scratch, int sig) {
    const std::string tag = std::to_string(sig);
    const std::string dir = scratch.path("int" + tag), outPath = scratch.path("o" + tag), errPath = scratch.path("e" + tag);
    const pid_t pid = test::spawnVdbsplat({"animate", vdbPath, "-o", dir, "--from", "8", "--to", "0.5", "--frames",
                                           "3000", "--size", "16x16", "--threads", "1"},
                                          outPath, errPath);
    ASSERT_GT(pid, 0);
    for (int i = 0; i < 1200 && !fs::exists(dir + "/frame_0003.png"); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
    ::kill(pid, sig);
    const int status = test::waitBounded(pid, 120);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 1);
    const std::string err = slurp(errPath);
    EXPECT_EQ(err.rfind("vdbsplat: error: interrupted after ", 0), 0u) << err;
    EXPECT_NE(err.find(" of 3000 frames"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(slurp(outPath).empty());
    test::expectNoTemporaries(dir);
    const size_t frames = countFiles(dir, "frame_");
    EXPECT_GE(frames, 4u);
    EXPECT_LT(frames, 3000u);
    EXPECT_NE(err.find("after " + std::to_string(frames) + " of"), std::string::npos) << err << frames;
    EXPECT_EQ(lines(slurp(dir + "/frames.csv")).size(), frames + 1);  // one row per finished frame
    for (size_t i = 0; i < frames; ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "/frame_%04zu.png", i);
        EXPECT_EQ(readImage(dir + name).width, 16) << name;
    }
}

TEST_F(AnimateCli, InterruptedByCtrlCBetweenFrames) { interruptAndCheck(vdb(), local_, SIGINT); }
TEST_F(AnimateCli, InterruptedBySigtermBetweenFrames) { interruptAndCheck(vdb(), local_, SIGTERM); }

}  // namespace
}  // namespace vdbsplat
