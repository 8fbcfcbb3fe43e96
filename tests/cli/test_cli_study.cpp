// tests/cli/test_cli_study.cpp — `vdbsplat study` run as the real binary, on a tiny generated
// sphere (16³ voxels) at 48×48 or smaller, reference spp 4 or less: every promised file with
// consistent contents (metrics.csv rows = volumes × kernels × views × modes, finite PSNR,
// decodable images, every <img> of index.html present), --resume (re-renders nothing, then
// exactly a deleted or damaged render, and only what changed settings change), refusal of a
// non-empty folder, --force, the zoom ladder, Ctrl-C/SIGTERM inside the study, bad input (one
// line, exit 1, nothing written), and the end-to-end check of the report in headless Chromium
// (skipped with a message when `chromium` is not installed: scripts/setup.sh --test).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "image/image.h"
#include "study/views.h"
#include "support/cli.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::slurp;
using test::spit;

using test::fields;
using test::lines;

/// Column name → index of metrics.csv's header.
std::map<std::string, size_t> columns(const std::string& header) {
    std::map<std::string, size_t> c;
    const auto f = fields(header);
    for (size_t i = 0; i < f.size(); ++i) c[f[i]] = i;
    return c;
}

/// Every src="…" of the <img> elements of an HTML text.
std::vector<std::string> imageSources(const std::string& html) {
    std::vector<std::string> out;
    static const std::regex re(R"re(<img [^>]*src="([^"]*)")re");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it)
        out.push_back((*it)[1]);
    return out;
}

/// Every regular file under @p dir with its modification time.
std::map<std::string, fs::file_time_type> fileTimes(const fs::path& dir) {
    std::map<std::string, fs::file_time_type> t;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) t[fs::relative(e.path(), dir).string()] = e.last_write_time();
    return t;
}

class StudyCli : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        scratch_ = new test::ScratchDir("study");
        const CliResult r = test::runVdbsplat("generate sphere --res 16 -o '" + vdb() + "'", scratch_->dir());
        ASSERT_EQ(r.rc, 0) << r.err;
    }
    static void TearDownTestSuite() {
        delete scratch_;
        scratch_ = nullptr;
    }
    static std::string vdb() { return scratch_->path("sphere.vdb"); }
    CliResult study(const std::string& args) const { return test::runVdbsplat("study '" + vdb() + "' " + args, local_.dir()); }
    std::string out(const std::string& name) const { return local_.path(name); }

    static test::ScratchDir* scratch_;
    test::ScratchDir local_{"study-run"};
};
test::ScratchDir* StudyCli::scratch_ = nullptr;

const char* kTiny = " --size 48x48 --spp 4 --modes hybrid,point --distances 2,0.5 --threads 1";

TEST_F(StudyCli, TinyStudyWritesEveryFile) {
    const std::string dir = out("tiny");
    const CliResult r = study("-o '" + dir + "'" + kTiny);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("6 renders (6 rendered, 0 kept)"), std::string::npos) << r.out;
    for (const char* f : {"index.html", "metrics.csv", "metrics.json", "command.txt"})
        EXPECT_TRUE(fs::is_regular_file(dir + "/" + f)) << f;
    EXPECT_EQ(slurp(dir + "/command.txt").rfind("vdbsplat study ", 0), 0u);
    EXPECT_NE(slurp(dir + "/command.txt").find("--modes hybrid,point"), std::string::npos);

    // metrics.csv: one row per view × mode (one volume, one kernel), finite metrics.
    const auto csv = lines(slurp(dir + "/metrics.csv"));
    ASSERT_EQ(csv.size(), 1u + 2 * 2);
    auto col = columns(csv[0]);
    for (const char* c : {"volume", "kernel", "view", "distance", "zoom", "mode", "psnr_db", "ssim", "seconds", "image"})
        ASSERT_TRUE(col.count(c)) << c << " in " << csv[0];
    std::set<std::string> seen;
    for (size_t i = 1; i < csv.size(); ++i) {
        const auto f = fields(csv[i]);
        ASSERT_EQ(f.size(), col.size()) << csv[i];
        EXPECT_EQ(f[col["volume"]], "sphere");
        EXPECT_EQ(f[col["kernel"]], "gaussian");
        const double psnr = std::stod(f[col["psnr_db"]]), ssim = std::stod(f[col["ssim"]]);
        EXPECT_TRUE(std::isfinite(psnr) && psnr > 10.0) << csv[i];
        EXPECT_GT(ssim, 0.0);
        EXPECT_LE(ssim, 1.0);
        EXPECT_GE(std::stod(f[col["seconds"]]), 0.0);
        EXPECT_NEAR(std::stod(f[col["zoom"]]) * std::stod(f[col["distance"]]), 1.0, 1e-9);
        const Image im = readImage(dir + "/" + f[col["image"]]);
        EXPECT_EQ(im.width, 48);
        EXPECT_EQ(im.height, 48);
        const Image heat = readImage(dir + "/" + f[col["error_image"]]);
        EXPECT_EQ(heat.width, 48);
        seen.insert(f[col["view"]] + "/" + f[col["mode"]]);
    }
    EXPECT_EQ(seen, (std::set<std::string>{"d2/hybrid", "d2/point", "d0_5/hybrid", "d0_5/point"}));
    EXPECT_EQ(fields(csv[1])[col["view"]], "d2");  // far to close

    // metrics.json holds the same rows.
    const auto j = nlohmann::json::parse(slurp(dir + "/metrics.json"));
    ASSERT_EQ(j["rows"].size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
        const auto f = fields(csv[i + 1]);
        EXPECT_EQ(j["rows"][i]["mode"], f[col["mode"]]);
        EXPECT_NEAR(j["rows"][i]["psnr_db"].get<double>(), std::stod(f[col["psnr_db"]]), 0.01);
    }
    EXPECT_EQ(j["reference_spp"], 4);

    // index.html: every image it names exists and decodes; the plots and the table are there.
    const std::string html = slurp(dir + "/index.html");
    const auto sources = imageSources(html);
    EXPECT_EQ(sources.size(), 2u * (2 + 2 * 3));  // per view: reference + crop, per mode: image, heat map, crop
    for (const std::string& s : sources) {
        EXPECT_EQ(s.find(".."), std::string::npos) << s;  // relative, inside the folder
        EXPECT_GT(readImage(dir + "/" + s).width, 0) << s;
    }
    EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg"));  // no network reference
    EXPECT_EQ(html.find("https://"), std::string::npos);
    size_t plots = 0;
    for (size_t p = html.find("<svg class=\"plot\""); p != std::string::npos; p = html.find("<svg class=\"plot\"", p + 1))
        ++plots;
    EXPECT_EQ(plots, 3u);  // PSNR, SSIM and time against zoom
    EXPECT_NE(html.find("<svg class=\"colourbar\""), std::string::npos);
    EXPECT_NE(html.find("<table class=\"metrics\""), std::string::npos);
    test::expectNoTemporaries(dir);
    for (const auto& e : fs::recursive_directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(StudyCli, ResumeKeepsRendersAndRedoesOnlyWhatIsMissingOrChanged) {
    const std::string dir = out("resume"), args = "-o '" + dir + "'" + kTiny;
    ASSERT_EQ(study(args).rc, 0);
    const auto before = fileTimes(dir);
    const std::string viewDir = dir + "/images/sphere/gaussian/d2";

    // A non-empty folder without --resume/--force: refused, one line, nothing touched.
    test::expectOneLineError(study(args), "not empty");
    EXPECT_EQ(fileTimes(dir), before);

    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a rewrite would show a new time
    const CliResult kept = study(args + " --resume");
    ASSERT_EQ(kept.rc, 0) << kept.err;
    EXPECT_NE(kept.out.find("(0 rendered, 6 kept)"), std::string::npos) << kept.out;
    const auto after = fileTimes(dir);
    for (const auto& [name, time] : before)
        if (name.ends_with(".exr") || (name.ends_with(".json") && name.rfind("images/", 0) == 0)) {
            EXPECT_EQ(after.at(name), time) << name << " was rewritten";
        }

    // A deleted image and a damaged record are rendered again, nothing else.
    fs::remove(viewDir + "/hybrid.exr");
    spit(dir + "/images/sphere/gaussian/d0_5/point.json", "{\"fingerprint\": \"damaged\"");
    spit(viewDir + "/point.exr.tmp4242.exr", "partial");
    const CliResult again = study(args + " --resume");
    ASSERT_EQ(again.rc, 0) << again.err;
    EXPECT_NE(again.out.find("(2 rendered, 4 kept)"), std::string::npos) << again.out;
    EXPECT_EQ(readImage(viewDir + "/hybrid.exr").width, 48);
    EXPECT_FALSE(fs::exists(viewDir + "/point.exr.tmp4242.exr"));
    EXPECT_EQ(fs::last_write_time(viewDir + "/reference.exr"), before.at("images/sphere/gaussian/d2/reference.exr"));
    // A deleted viewing PNG comes back from the kept EXR without a render.
    fs::remove(viewDir + "/point.png");
    const CliResult png = study(args + " --resume");
    EXPECT_NE(png.out.find("(0 rendered, 6 kept)"), std::string::npos) << png.out;
    EXPECT_EQ(readImage(viewDir + "/point.png").width, 48);

    // A render whose record an older build wrote (no cutoff, compositing, slab thickness or second
    // --lod cap in its identity: they were left out at their defaults, and --cutoff's was 1e-4) is
    // rendered again, not kept: its fingerprint is not today's.
    {
        nlohmann::json side = nlohmann::json::parse(slurp(viewDir + "/hybrid.json"));
        nlohmann::json identity = side.at("made_from");
        ASSERT_TRUE(identity.at("settings").contains("cutoff"));
        for (const char* key : {"cutoff", "compositing", "slab_thickness", "lod_coarse"}) identity["settings"].erase(key);
        side["made_from"] = identity;
        side["fingerprint"] = study::fnv1a(identity.dump());
        spit(viewDir + "/hybrid.json", side.dump(2));
        const CliResult older = study(args + " --resume");
        EXPECT_NE(older.out.find("(1 rendered, 5 kept)"), std::string::npos) << older.out;
    }

    // Other forward settings: the forward modes again, the references kept; other spp: the reverse.
    const CliResult threshold = study(args + " --resume --threshold 2");
    EXPECT_NE(threshold.out.find("(4 rendered, 2 kept)"), std::string::npos) << threshold.out;
    const std::string spp = "-o '" + dir + "' --size 48x48 --spp 1 --modes hybrid,point --distances 2,0.5 --threshold 2";
    const CliResult refs = study(spp + " --resume");
    EXPECT_NE(refs.out.find("(2 rendered, 4 kept)"), std::string::npos) << refs.out;
    EXPECT_EQ(lines(slurp(dir + "/command.txt")).size(), 7u);  // one line per run that started

    // --force starts afresh.
    const CliResult forced = study(args + " --force");
    ASSERT_EQ(forced.rc, 0) << forced.err;
    EXPECT_NE(forced.out.find("(6 rendered, 0 kept)"), std::string::npos) << forced.out;
    EXPECT_EQ(lines(slurp(dir + "/command.txt")).size(), 1u);
    test::expectNoTemporaries(dir);
}

TEST_F(StudyCli, ZoomLadderAndStandardViews) {
    const std::string dir = out("ladder");
    const CliResult r = study("-o '" + dir + "' --views ladder,standard --modes splat --size 24x24 --spp 1 --threads 1");
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto csv = lines(slurp(dir + "/metrics.csv"));
    auto col = columns(csv[0]);
    std::vector<double> zooms;
    for (size_t i = 1; i < csv.size(); ++i) zooms.push_back(std::stod(fields(csv[i])[col["zoom"]]));
    // 1/8 … 8 with close (distance 0.35) between 2× and 4×: far to close, distances 8 and 1 once.
    const std::vector<double> expected{0.125, 0.25, 0.5, 1, 2, 1 / 0.35, 4, 8};
    ASSERT_EQ(zooms.size(), expected.size()) << slurp(dir + "/metrics.csv");
    for (size_t i = 0; i < zooms.size(); ++i) EXPECT_NEAR(zooms[i], expected[i], 1e-6);
}

TEST_F(StudyCli, BadInputOneLineNothingWritten) {
    const std::string dir = out("never");
    const std::string o = " -o '" + dir + "' --size 24x24 --spp 1";
    spit(out("garbage.vdb"), "not a vdb file");
    struct Case {
        std::string args, needle;
    };
    const std::vector<Case> cases{
        {"--modes hybrid,nosuch" + o, "--modes: unknown mode 'nosuch'"},
        {"--modes reference" + o, "--modes: 'reference'"},
        {"--modes hybrid,hybrid" + o, "--modes: 'hybrid' given more than once"},
        {"--modes ''" + o, "--modes: empty item"},
        {"--modes hybrid,,point" + o, "--modes: empty item"},
        {"--kernels nosuch" + o, "--kernels: "},  // the message after it is the kernel parser's
        {"--kernels ''" + o, "--kernels: empty item"},
        {"--distances nan" + o, "--distances: expected a finite number"},
        {"--distances -1" + o, "--distances: each must be a number in [0.0001, 1e6)"},
        {"--distances 1,0" + o, "--distances: each must be a number in [0.0001, 1e6)"},
        {"--distances 1e-300" + o, "--distances: each must be a number in [0.0001, 1e6)"},
        {"--distances 1e6" + o, "--distances: each must be a number in [0.0001, 1e6)"},
        {"--views nosuch" + o, "--views: unknown views 'nosuch'"},
        {"--views ladder --base nan" + o, "--base: expected a finite number"},
        {"--views ladder --base -2" + o, "--base: must be a number in [0.001, 1e5)"},
        {"--views ladder --base 1e-7" + o, "--base: must be a number in [0.001, 1e5)"},
        {"--base 2" + o, "--base: needs --views ladder"},
        {"--spp 0" + o, "--spp"},
        {"--size 0x5" + o, "--size"},
        {"--threshold nan" + o, "--threshold"},
        {"--mode hybrid" + o, "unknown option '--mode'"},
        {"--distance 1" + o, "unknown option '--distance'"},
        {"--resume --force" + o, "--resume: not with --force"},
        {"--size 24x24", "-o is required"},
        {"'" + out("missing.vdb") + "'" + o, out("missing.vdb")},
        {"'" + out("garbage.vdb") + "'" + o, out("garbage.vdb")},
        {"'" + vdb() + "'" + o, "given more than once"},
        {"-o '" + out("no/such/parent") + "' --size 24x24", "parent folder does not exist"},
        {"-o '" + out("garbage.vdb") + "' --size 24x24", "exists and is not a folder"},
    };
    for (const Case& c : cases) {
        const CliResult r = study(c.args);
        test::expectOneLineError(r, c.needle, c.args);
        if (c.args.find("nosuch") != std::string::npos) {
            EXPECT_NE(r.err.find("nosuch"), std::string::npos) << r.err;
        }
    }
    EXPECT_FALSE(fs::exists(dir));
    // No input at all.
    test::expectOneLineError(test::runVdbsplat("study -o '" + dir + "'", local_.dir()), "missing input");
    EXPECT_FALSE(fs::exists(dir));
}

/// Starts a long study (no shell: the signals at their default, as in a terminal; views are
/// rendered far to close), waits until its first view is finished, sends @p sig, and checks the interruption contract; then
/// --resume keeps every finished render.
void interruptAndCheck(const std::string& vdbPath, const test::ScratchDir& scratch, int sig) {
    const std::string tag = std::to_string(sig);
    const std::string dir = scratch.path("int" + tag), outPath = scratch.path("o" + tag), errPath = scratch.path("e" + tag);
    std::string distances;
    for (int i = 0; i < 60; ++i) distances += (i ? "," : "") + std::to_string(5.0 - 0.05 * i);  // far to close
    const std::vector<std::string> args{"study", vdbPath, "-o", dir, "--distances", distances, "--modes", "hybrid,splat",
                                        "--size", "24x24", "--spp", "4", "--threads", "1"};
    const pid_t pid = test::spawnVdbsplat(args, outPath, errPath);
    ASSERT_GT(pid, 0);
    const std::string first = dir + "/images/sphere/gaussian/d5/splat.json";  // the first view's last render
    for (int i = 0; i < 2400 && !fs::exists(first); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
    ASSERT_TRUE(fs::exists(first));
    ::kill(pid, sig);
    const int status = test::waitBounded(pid, 120);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 1);
    const std::string err = slurp(errPath);
    EXPECT_EQ(err.rfind("vdbsplat: error: interrupted (", 0), 0u) << err;
    EXPECT_NE(err.find(" of 180 renders"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(slurp(outPath).empty());
    EXPECT_FALSE(fs::exists(dir + "/index.html"));  // the report is written once the study is complete
    size_t finished = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        EXPECT_EQ(name.find(".tmp"), std::string::npos) << e.path();
        if (name.ends_with(".json")) {  // a finished render: its images are whole
            ++finished;
            const std::string stem = e.path().string().substr(0, e.path().string().size() - 5);
            EXPECT_EQ(readImage(stem + ".exr").width, 24) << stem;
            EXPECT_EQ(readImage(stem + ".png").width, 24) << stem;
        }
    }
    EXPECT_GE(finished, 3u);
    const CliResult resumed = test::runVdbsplat(
        "study '" + vdbPath + "' -o '" + dir + "' --distances 5 --modes hybrid,splat --size 24x24 --spp 4 --resume",
        scratch.dir());
    ASSERT_EQ(resumed.rc, 0) << resumed.err;
    EXPECT_NE(resumed.out.find("(0 rendered, 3 kept)"), std::string::npos) << resumed.out;
}

TEST_F(StudyCli, InterruptedByCtrlC) { interruptAndCheck(vdb(), local_, SIGINT); }
TEST_F(StudyCli, InterruptedBySigterm) { interruptAndCheck(vdb(), local_, SIGTERM); }

TEST_F(StudyCli, KilledHardKeepsFinishedRendersAndResumeCleansUp) {
    // SIGKILL cannot be caught: whatever was being written is left as a temporary at most, never
    // as a half-written file under its own name; --resume removes the temporaries and keeps
    // every render whose record (.json, written last) is there.
    const std::string dir = out("killed"), outPath = out("o9"), errPath = out("e9");
    std::string distances;
    for (int i = 0; i < 60; ++i) distances += (i ? "," : "") + std::to_string(5.0 - 0.05 * i);
    const pid_t pid = test::spawnVdbsplat({"study", vdb(), "-o", dir, "--distances", distances, "--modes", "hybrid,splat",
                                           "--size", "24x24", "--spp", "4", "--threads", "1"},
                                          outPath, errPath);
    ASSERT_GT(pid, 0);
    const std::string first = dir + "/images/sphere/gaussian/d5/splat.json";
    for (int i = 0; i < 2400 && !fs::exists(first); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
    ASSERT_TRUE(fs::exists(first));
    ::kill(pid, SIGKILL);
    const int status = test::waitBounded(pid, 60);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    EXPECT_FALSE(fs::exists(dir + "/index.html"));
    size_t finished = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string p = e.path().string();
        if (!p.ends_with(".json") || p.find(".tmp") != std::string::npos) continue;
        ++finished;
        const std::string stem = p.substr(0, p.size() - 5);
        EXPECT_EQ(readImage(stem + ".exr").width, 24) << stem;
        EXPECT_EQ(readImage(stem + ".png").width, 24) << stem;
        EXPECT_TRUE(nlohmann::json::accept(slurp(p))) << p;  // parses as JSON
    }
    EXPECT_GE(finished, 3u);
    const CliResult resumed = test::runVdbsplat(
        "study '" + vdb() + "' -o '" + dir + "' --distances 5,4.95 --modes hybrid,splat --size 24x24 --spp 4 --resume",
        local_.dir());
    ASSERT_EQ(resumed.rc, 0) << resumed.err;
    EXPECT_NE(resumed.out.find(" kept)"), std::string::npos) << resumed.out;
    EXPECT_EQ(resumed.out.find("(6 rendered"), std::string::npos) << resumed.out;  // the first view was kept
    for (const auto& e : fs::recursive_directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(StudyCli, StudyFileRunsAndIsValidatedLikeFlags) {
    const std::string spec = out("study.json"), dir = out("spec");
    spit(spec, "{\"volumes\": [\"" + vdb() + "\"], \"modes\": [\"hybrid\", \"point\"], \"distances\": [2, 0.5],\n"
               " \"size\": [40, 32], \"spp\": 2, \"tf\": \"grey\", \"threshold\": 1}");
    const CliResult r = test::runVdbsplat("study --spec '" + spec + "' -o '" + dir + "' --threads 1", local_.dir());
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("6 renders (6 rendered, 0 kept)"), std::string::npos) << r.out;
    EXPECT_EQ(lines(slurp(dir + "/metrics.csv")).size(), 5u);
    EXPECT_EQ(readImage(dir + "/images/sphere/gaussian/d2/hybrid.png").width, 40);
    EXPECT_NE(slurp(dir + "/command.txt").find("--spec"), std::string::npos);

    const std::string never = out("never-spec");
    struct Case {
        std::string content, needle, extra;
    };
    const std::string v = "\"volumes\": [\"" + vdb() + "\"]";
    const std::vector<Case> cases{
        {"not json", "not valid JSON", ""},
        {"[1, 2]", "expected a JSON object, got array", ""},
        {"{\"modes\": [\"hybrid\"]}", "volumes: missing", ""},
        {"{\"volumes\": []}", "volumes: empty list", ""},
        {"{\"volumes\": \"a.vdb\"}", "volumes: expected an array", ""},
        {"{" + v + ", \"nosuch\": 1}", "unknown key 'nosuch'", ""},
        {"{" + v + ", \"modes\": [\"hybrid,point\"]}", "modes[0]: 'hybrid,point' holds a comma", ""},
        {"{" + v + ", \"modes\": [\"nosuch\"]}", "modes: unknown mode 'nosuch'", ""},
        {"{" + v + ", \"modes\": []}", "modes: empty list", ""},
        {"{" + v + ", \"distances\": [1, \"a\"]}", "distances[1]: expected a number, got string", ""},
        {"{" + v + ", \"distances\": [-1]}", "distances: each must be a number in", ""},
        {"{" + v + ", \"size\": [40]}", "size: expected [width, height]", ""},
        {"{" + v + ", \"size\": [0, 40]}", "size width: expected an integer in [1, 16384]", ""},
        {"{" + v + ", \"spp\": 1.5}", "spp: expected an integer", ""},
        {"{" + v + ", \"base\": 2}", "base: needs --views ladder", ""},
        {"{" + v + ", \"tf\": \"\"}", "tf: empty string", ""},
        {"{" + v + ", \"views\": [[\"standard\"]]}", "nested deeper than 2", ""},
        {"{" + v + ", \"spp\": 1e999}", "not valid JSON", ""},
        {"{" + v + ", \"modes\": [\"hybrid\"]}", "modes: also given as --modes", " --modes point"},
        {"{" + v + "}", "volumes: also given on the command line", " '" + vdb() + "'"},
    };
    for (const Case& c : cases) {
        spit(spec, c.content);
        const CliResult bad =
            test::runVdbsplat("study --spec '" + spec + "' -o '" + never + "'" + c.extra, local_.dir());
        test::expectOneLineError(bad, c.needle, c.content);
        EXPECT_NE(bad.err.find(spec), std::string::npos) << bad.err;  // names the file
    }
    test::expectOneLineError(test::runVdbsplat("study --spec '" + out("none.json") + "' -o '" + never + "'", local_.dir()),
                             "no such study file");
    EXPECT_FALSE(fs::exists(never));
}

TEST_F(StudyCli, OneTransferFunctionPerVolume) {
    const std::string second = out("ball.vdb"), dir = out("tfs");
    ASSERT_EQ(test::runVdbsplat("generate sphere --res 12 -o '" + second + "'", local_.dir()).rc, 0);
    const CliResult r = study("'" + second + "' -o '" + dir + "' --tfs grey,fire --modes hybrid --distances 1 --size 24x24 --spp 1");
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto csv = lines(slurp(dir + "/metrics.csv"));
    ASSERT_EQ(csv.size(), 3u);
    auto col = columns(csv[0]);
    EXPECT_EQ(fields(csv[1])[col["tf"]], "grey");
    EXPECT_EQ(fields(csv[2])[col["tf"]], "fire");
    // grey is grey; fire is not.
    const Image g = readImage(dir + "/images/sphere/gaussian/d1/reference.exr");
    const Image f = readImage(dir + "/images/ball/gaussian/d1/reference.exr");
    const auto& gc = g.at(12, 12);
    const auto& fc = f.at(12, 12);
    EXPECT_NEAR(gc.x, gc.z, 1e-5);
    EXPECT_GT(std::abs(fc.x - fc.z), 1e-3);
    const std::string o = " -o '" + out("never-tfs") + "' --size 24x24";
    test::expectOneLineError(study("'" + second + "' --tfs grey" + o), "--tfs: 1 transfer functions for 2 volumes");
    test::expectOneLineError(study("--tfs grey --tf grey" + o), "--tfs: not with --tf");
    test::expectOneLineError(study("--tfs nosuch" + o), "--tfs: unknown transfer function");
    test::expectOneLineError(study("--tfs ''" + o), "--tfs: empty item");
    EXPECT_FALSE(fs::exists(out("never-tfs")));
}

TEST_F(StudyCli, RenderFlagsPassThroughEmissionIncluded) {
    // The render flags reach every render of the study: an emission grid (loaded once with its
    // volume) makes other images than without it, and --resume tells the two apart.
    const std::string fire = out("explosion.vdb"), dir = out("emission");
    ASSERT_EQ(test::runVdbsplat("generate explosion --res 24 -o '" + fire + "'", local_.dir()).rc, 0);
    const std::string args = "study '" + fire + "' -o '" + dir + "' --modes hybrid --distances 1 --size 24x24 --spp 1";
    const CliResult plain = test::runVdbsplat(args, local_.dir());
    ASSERT_EQ(plain.rc, 0) << plain.err;
    const Image without = readImage(dir + "/images/explosion/gaussian/d1/hybrid.exr");
    const CliResult lit = test::runVdbsplat(args + " --emission temperature --resume", local_.dir());
    ASSERT_EQ(lit.rc, 0) << lit.err;
    EXPECT_NE(lit.out.find("(2 rendered, 0 kept)"), std::string::npos) << lit.out;
    const Image with = readImage(dir + "/images/explosion/gaussian/d1/hybrid.exr");
    double added = 0.0;
    for (size_t i = 0; i < with.pixels.size(); ++i) added += with.pixels[i].x - without.pixels[i].x;
    EXPECT_GT(added, 0.0);  // emission adds light
    test::expectOneLineError(test::runVdbsplat(args + " --emission nosuch --force", local_.dir()), "nosuch");
}

/// The value of attribute @p name of the element with id="selfcheck" in a DOM dump ("" if absent).
std::string selfcheck(const std::string& dom, const std::string& name) {
    const size_t p = dom.find("id=\"selfcheck\"");
    if (p == std::string::npos) return "";
    const size_t end = dom.find('>', p);
    const std::regex re(name + "=\"([^\"]*)\"");
    std::smatch m;
    const std::string tag = dom.substr(p, end - p);
    return std::regex_search(tag, m, re) ? std::string(m[1]) : "";
}

TEST_F(StudyCli, ReportLoadsInHeadlessChromium) {
    const CliResult which = test::runShell("command -v chromium", local_.dir());
    if (which.rc != 0)
        GTEST_SKIP() << "chromium is not installed: the report's end-to-end test is skipped "
                        "(scripts/setup.sh --test installs it)";
    const std::string dir = out("chromium");
    ASSERT_EQ(study("-o '" + dir + "'" + kTiny).rc, 0);
    auto dump = [&] {
        const std::string profile = local_.path("chromium-profile");
        return test::runShell("timeout -k 5 120 chromium --headless --disable-gpu --no-sandbox --user-data-dir='" +
                                  profile + "' --dump-dom 'file://" + fs::absolute(dir).string() + "/index.html'",
                              local_.dir());
    };
    const CliResult r = dump();
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::string dom = r.out;
    const size_t images = imageSources(slurp(dir + "/index.html")).size();
    ASSERT_GT(images, 0u);
    EXPECT_EQ(selfcheck(dom, "data-status"), "ok") << dom.substr(0, 2000);
    EXPECT_EQ(selfcheck(dom, "data-images"), std::to_string(images));
    EXPECT_EQ(selfcheck(dom, "data-loaded"), std::to_string(images));  // naturalWidth > 0 for every <img>
    EXPECT_EQ(selfcheck(dom, "data-tables"), "4");                     // rows of the metrics table
    EXPECT_EQ(selfcheck(dom, "data-plots"), std::to_string(3 * 2 + 1));  // 3 plots × 2 modes + reference time
    // The check can fail: a missing image is seen as one.
    fs::remove(dir + "/images/sphere/gaussian/d2/point-error.png");
    const CliResult broken = dump();
    ASSERT_EQ(broken.rc, 0) << broken.err;
    EXPECT_EQ(selfcheck(broken.out, "data-status"), "missing");
    EXPECT_EQ(selfcheck(broken.out, "data-loaded"), std::to_string(images - 1));
}

}  // namespace
}  // namespace vdbsplat
