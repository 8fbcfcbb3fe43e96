// tests/cli/test_cli_bench.cpp — `vdbsplat bench` end to end on a small generated sphere:
// the JSON report's shape (3 distances × 3 modes, every run, ratios to hybrid, the share
// of splats per mode), mode/distance subsets, --help, and one-line errors with a non-zero
// exit and no JSON file for bad input. Timings are never asserted: it is a benchmark.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "support/cli.h"

namespace {

namespace fs = std::filesystem;
using vdbsplat::test::CliResult;
using vdbsplat::test::slurp;

/// A scratch folder holding a 24³ generated sphere, removed afterwards.
class BenchCli : public ::testing::Test {
protected:
    void SetUp() override {
        const CliResult g = run("generate sphere -o '" + path("s.vdb") + "' --res 24");
        ASSERT_EQ(g.rc, 0) << g.err;
        ASSERT_TRUE(fs::exists(path("s.vdb")));
    }
    std::string path(const std::string& name) const { return scratch_.path(name); }

    /// Runs `vdbsplat <args>` and captures its exit code, stdout and stderr.
    CliResult run(const std::string& args) const { return vdbsplat::test::runVdbsplat(args, scratch_.dir()); }
    CliResult bench(const std::string& args) const { return run("bench '" + path("s.vdb") + "' " + args); }

    /// Expects a failure with exactly one line "vdbsplat: error: …" containing @p what, and no JSON.
    void expectError(const CliResult& r, const std::string& what, const std::string& json) const {
        vdbsplat::test::expectOneLineError(r, what);
        EXPECT_FALSE(fs::exists(json)) << json;
        vdbsplat::test::expectNoTemporaries(scratch_.dir());
    }

    vdbsplat::test::ScratchDir scratch_{"bench"};
};

const nlohmann::json& resultFor(const nlohmann::json& j, double distance, const std::string& mode) {
    for (const auto& r : j.at("results"))
        if (r.at("distance").get<double>() == distance && r.at("mode") == mode) return r;
    throw std::runtime_error("no result for " + mode + " at " + std::to_string(distance));
}

TEST_F(BenchCli, HelpExitsZero) {
    const CliResult r = run("bench --help");
    EXPECT_EQ(r.rc, 0);
    EXPECT_NE(r.out.find("usage: vdbsplat bench FILE.vdb"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--distances"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(BenchCli, ThreeViewsThreeModesJson) {
    const std::string json = path("out.json");
    const CliResult r = bench("--size 48x48 --runs 2 --warmup 0 --json '" + json + "'");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_NE(r.out.find("ratio_to_hybrid"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("median over distances"), std::string::npos) << r.out;

    const auto j = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(j.at("volume"), path("s.vdb"));
    EXPECT_EQ(j.at("grid"), "density");
    EXPECT_EQ(j.at("active_voxels").get<uint64_t>(), 6272u);  // `generate sphere --res 24`
    EXPECT_EQ(j.at("width"), 48);
    EXPECT_EQ(j.at("height"), 48);
    EXPECT_EQ(j.at("runs"), 2);
    EXPECT_GE(j.at("threads").get<int>(), 1);
    EXPECT_GE(j.at("machine").get<int>(), 0);

    const auto& results = j.at("results");
    ASSERT_EQ(results.size(), 9u);
    // Distance-major, modes in the order given: 8, 1, 0.35 × hybrid, splat, point.
    const double distances[] = {8.0, 1.0, 0.35};
    const char* modes[] = {"hybrid", "splat", "point"};
    for (int i = 0; i < 9; ++i) {
        const auto& res = results[i];
        EXPECT_DOUBLE_EQ(res.at("distance").get<double>(), distances[i / 3]) << i;
        EXPECT_EQ(res.at("mode"), modes[i % 3]) << i;
        ASSERT_EQ(res.at("seconds").size(), 2u) << i;
        const double lo = std::min(res["seconds"][0].get<double>(), res["seconds"][1].get<double>());
        EXPECT_GT(lo, 0.0);
        EXPECT_DOUBLE_EQ(res.at("min_seconds").get<double>(), lo);
        EXPECT_GE(res.at("median_seconds").get<double>(), lo);
        for (const char* stage : {"stream", "project", "rasterize", "composite"})
            EXPECT_GE(res.at("stages").at(stage).get<double>(), 0.0) << stage;
        const uint64_t points = res.at("points"), splats = res.at("splats"), culled = res.at("culled");
        EXPECT_GT(points + splats, 0u) << i;
        EXPECT_LE(points + splats + culled, 6272u) << i;
        EXPECT_DOUBLE_EQ(res.at("splat_fraction").get<double>(), double(splats) / double(points + splats)) << i;
        if (res["mode"] == "hybrid") {
            EXPECT_TRUE(res.at("ratio_to_hybrid").is_null()) << i;
        } else {
            ASSERT_TRUE(res.at("ratio_to_hybrid").is_number()) << i;
            EXPECT_GT(res["ratio_to_hybrid"].get<double>(), 0.0) << i;
            const double hybrid = results[i - i % 3].at("median_seconds").get<double>();
            EXPECT_NEAR(res["ratio_to_hybrid"].get<double>(), res["median_seconds"].get<double>() / hybrid, 1e-9);
        }
        if (res["mode"] == "splat") {
            EXPECT_EQ(res["splat_fraction"].get<double>(), 1.0) << i;
        }
        if (res["mode"] == "point") {
            // Point mode draws every voxel in front of the eye as a point; only a voxel at or
            // behind the eye plane takes the splat path (and counts as a splat if its kernel
            // straddles the eye). At 0.35 the default framing keeps the eye outside this
            // sphere's support, so point mode draws no splats at any of the three views.
            EXPECT_EQ(res["splat_fraction"].get<double>(), 0.0) << i;
            EXPECT_EQ(splats, 0u) << i;
        }
    }
    // Hybrid turns to splats as the eye comes closer (voxels magnify past the 1 px threshold).
    const double far = resultFor(j, 8.0, "hybrid").at("splat_fraction");
    const double mid = resultFor(j, 1.0, "hybrid").at("splat_fraction");
    const double near = resultFor(j, 0.35, "hybrid").at("splat_fraction");
    EXPECT_LE(far, mid);
    EXPECT_LE(mid, near);
    EXPECT_LT(far, near);

    const auto& ratios = j.at("ratios");
    EXPECT_FALSE(ratios.contains("hybrid"));
    for (const char* mode : {"splat", "point"}) {
        ASSERT_TRUE(ratios.at(mode).is_number()) << mode;
        std::vector<double> per;
        for (double d : distances) per.push_back(resultFor(j, d, mode).at("ratio_to_hybrid"));
        std::sort(per.begin(), per.end());
        EXPECT_DOUBLE_EQ(ratios[mode].get<double>(), per[1]) << mode;  // median of three
    }
}

TEST_F(BenchCli, ModeAndDistanceSubsets) {
    const std::string json = path("sub.json");
    const CliResult r =
        bench("--size 24x16 --runs 1 --warmup 1 --modes point,hybrid --distances 2,0.5 --json=" + json);
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(j.at("width"), 24);
    EXPECT_EQ(j.at("height"), 16);
    ASSERT_EQ(j.at("results").size(), 4u);
    EXPECT_EQ(j["results"][0].at("mode"), "point");
    EXPECT_EQ(j["results"][1].at("mode"), "hybrid");
    EXPECT_DOUBLE_EQ(j["results"][2].at("distance").get<double>(), 0.5);
    EXPECT_EQ(j["results"][0].at("seconds").size(), 1u);  // the warmup round is not recorded
    EXPECT_TRUE(j["results"][0].at("ratio_to_hybrid").is_number());
    EXPECT_TRUE(j["results"][1].at("ratio_to_hybrid").is_null());
    EXPECT_EQ(j.at("ratios").size(), 1u);
    EXPECT_TRUE(j["ratios"].at("point").is_number());
}

TEST_F(BenchCli, WithoutHybridThereAreNoRatios) {
    const std::string json = path("nohybrid.json");
    const CliResult r = bench("--size 16x16 --runs 1 --warmup 0 --modes splat --distances 1 --json " + json);
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(j.at("results").size(), 1u);
    EXPECT_TRUE(j["results"][0].at("ratio_to_hybrid").is_null());
    EXPECT_TRUE(j.at("ratios").at("splat").is_null());
}

TEST_F(BenchCli, ReferenceIsAllowedWithAWarning) {
    const std::string json = path("ref.json");
    const CliResult r =
        bench("--size 8x8 --runs 1 --warmup 0 --modes hybrid,reference --distances 1 --json " + json);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.err.rfind("vdbsplat: warning: reference mode", 0), 0u) << r.err;
    const auto j = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(j.at("results").size(), 2u);
    EXPECT_TRUE(j["results"][1].at("splat_fraction").is_null());  // no points or splats drawn
    EXPECT_TRUE(j["results"][1].at("ratio_to_hybrid").is_number());
}

TEST_F(BenchCli, LensRaysTablesAndTheVoxelLimitReachTheRenders) {
    const std::string json = path("flags.json");
    const CliResult r = bench("--size 8x8 --runs 1 --warmup 0 --modes hybrid,reference --distances 1 --fov 50 "
                              "--spp 4 --tables '" + std::string(VDBSPLAT_SOURCE_DIR) + "/tables' --max-voxels 100000 --json " + json);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("fov 50"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(slurp(json));
    EXPECT_DOUBLE_EQ(j.at("fov").get<double>(), 50.0);
    EXPECT_EQ(j.at("spp"), 4);
    EXPECT_EQ(j.at("max_voxels"), 100000);
    // The reference traced --spp rays per pixel (of the image and its filter border): 4× --spp 1's.
    const std::string one = path("spp1.json");
    ASSERT_EQ(bench("--size 8x8 --runs 1 --warmup 0 --modes reference --distances 1 --fov 50 --spp 1 --json " + one).rc, 0);
    const auto j1 = nlohmann::json::parse(slurp(one));
    EXPECT_EQ(j["results"][1].at("rays").get<uint64_t>(), 4 * j1["results"][0].at("rays").get<uint64_t>());
    // The limit is the render's: a grid above it is refused before any timing, with no JSON.
    const std::string none = path("limit.json");
    expectError(bench("--runs 1 --max-voxels 10 --json " + none), "--max-voxels", none);
    expectError(bench("--runs 1 --tables '" + path("nope") + "' --json " + none), "--tables", none);
    expectError(bench("--runs 1 --fov 180 --json " + none), "--fov", none);
}

TEST_F(BenchCli, BadInput) {
    const std::string json = path("bad.json");
    const std::string j = " --size 16x16 --runs 1 --warmup 0 --json '" + json + "'";
    expectError(run("bench '" + path("nope.vdb") + "'" + j), path("nope.vdb") + ": no such file", json);
    expectError(run("bench" + j), "missing input .vdb file", json);
    expectError(bench("--runs 0 --json '" + json + "'"), "--runs: expected an integer in [1, 1000]", json);
    expectError(bench("--runs 1001 --json '" + json + "'"), "--runs", json);
    expectError(bench("--warmup -1 --json '" + json + "'"), "--warmup", json);
    expectError(bench("--modes bogus" + j), "--modes: unknown mode 'bogus'", json);
    expectError(bench("--modes hybrid,,point" + j), "--modes: empty item", json);
    expectError(bench("--modes hybrid,hybrid" + j), "--modes: 'hybrid' given more than once", json);
    expectError(bench("--size 0x0 --runs 1 --json '" + json + "'"), "--size", json);
    expectError(bench("--size 48 --runs 1 --json '" + json + "'"), "--size", json);
    expectError(bench("--distances 8,,1" + j), "--distances: empty item", json);
    expectError(bench("--distances 8,abc" + j), "--distances: expected a number, got 'abc'", json);
    expectError(bench("--distances 8,-1" + j), "--distances: each must be a positive number", json);
    expectError(bench("--distances 0" + j), "--distances", json);
    expectError(bench("--distances=" + j), "--distances", json);
    expectError(bench("--threshold 0" + j), "--threshold", json);
    expectError(bench("--threads 2000" + j), "--threads", json);
    expectError(bench("--footprint fast" + j), "--footprint", json);
    expectError(bench("--tf nosuchpreset" + j), "nosuchpreset", json);
    expectError(bench("--grid nosuchgrid" + j), "nosuchgrid", json);
    expectError(bench("--mode splat" + j), "unknown option '--mode'", json);
    const std::string deep = path("no/such/dir/b.json");
    expectError(bench("--size 16x16 --runs 1 --json '" + deep + "'"), deep, deep);
}

}  // namespace
