// tests/cli/test_cli_volume.cpp — the `info`, `generate` and `convert` commands run as
// the real binary: --help, exit codes, output files, and for every bad input a non-zero
// exit, one stderr line "vdbsplat: error: …" naming the file or flag, and no output file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli.h"

namespace {

namespace fs = std::filesystem;
using Result = vdbsplat::test::CliResult;
using vdbsplat::test::slurp;

class CliVolume : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }

    /// Runs `vdbsplat <args>` and captures its exit code, stdout and stderr.
    Result run(const std::string& args) const { return vdbsplat::test::runVdbsplat(args, scratch_.dir()); }

    /// Expects exit code 1 with a single "vdbsplat: error:" line that contains @p needle, and no @p output.
    void expectError(const std::string& args, const std::string& needle, const std::string& output = "") const {
        const Result r = run(args);
        EXPECT_EQ(r.rc, 1) << args;
        vdbsplat::test::expectOneLineError(r, needle, args);
        if (!output.empty()) {
            EXPECT_FALSE(fs::exists(output)) << args;
        }
        vdbsplat::test::expectNoTemporaries(scratch_.dir());
    }

    std::string writeBytes(const std::string& name, size_t n) const {
        std::string bytes(n, '\0');
        for (size_t i = 0; i < n; ++i) bytes[i] = char(i % 7 == 0 ? 0 : 1 + i % 200);
        std::ofstream(path(name), std::ios::binary) << bytes;
        return path(name);
    }

    vdbsplat::test::ScratchDir scratch_{"cli-volume"};
};

TEST_F(CliVolume, HelpExitsZero) {
    for (const char* cmd : {"info", "generate", "convert"}) {
        const Result r = run(std::string(cmd) + " --help");
        EXPECT_EQ(r.rc, 0) << cmd;
        EXPECT_NE(r.out.find("usage: vdbsplat " + std::string(cmd)), std::string::npos) << r.out;
        EXPECT_TRUE(r.err.empty()) << r.err;
    }
}

TEST_F(CliVolume, GenerateThenInfo) {
    const std::string out = path("cb.vdb");
    Result r = run("generate checkerbox -o " + out);
    ASSERT_EQ(r.rc, 0) << r.err;
    ASSERT_TRUE(fs::exists(out));
    r = run("info " + out);
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("'density'"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("active voxels: 1000000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(0, 0, 0) .. (99, 99, 99)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("voxel size:    (1, 1, 1)"), std::string::npos) << r.out;
    r = run("generate cloud --active 20000 --seed 5 -o " + path("cloud.vdb"));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("cloud"), std::string::npos) << r.out;
    r = run("generate marschner-lobb --res 17 -o " + path("ml.vdb"));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(run("info " + path("ml.vdb")).out.find("active voxels: 4913"), std::string::npos);
}

TEST_F(CliVolume, GenerateBadInput) {
    const std::string out = path("x.vdb");
    expectError("generate teapot -o " + out, "teapot", out);
    expectError("generate sphere --res abc -o " + out, "--res", out);
    expectError("generate sphere --res 0 -o " + out, "--res", out);
    expectError("generate sphere --res 5000 -o " + out, "--res", out);
    expectError("generate checkerbox --res 4096 -o " + out, "--res", out);  // 6.9e10 voxels
    expectError("generate sphere --res 12x -o " + out, "--res", out);
    expectError("generate cloud --active 0 -o " + out, "--active", out);
    expectError("generate cloud --active 3000000000 -o " + out, "--active", out);
    expectError("generate cloud --active 1e5 -o " + out, "--active", out);
    expectError("generate cloud --seed -3 -o " + out, "--seed", out);
    expectError("generate sphere --active 100 -o " + out, "--active", out);
    expectError("generate cloud --res 10 -o " + out, "--res", out);
    expectError("generate sphere", "-o");
    expectError("generate -o " + out, "KIND", out);
    expectError("generate sphere --bogus 1 -o " + out, "--bogus", out);
    expectError("generate sphere -o " + path("no/such/dir/x.vdb"), "no/such/dir");
}

// `convert --spacing 1,1,2.5` keeps the spacing per axis, and the grid renders (ellipsoid kernels).
TEST_F(CliVolume, AnisotropicSpacingConvertsAndRenders) {
    const std::string raw = writeBytes("a.raw", 10 * 8 * 6);
    const std::string out = path("a.vdb");
    Result r = run("convert " + raw + " -o " + out + " --dims 10,8,6 --type uint8 --spacing 1,1,2.5");
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run("info " + out);
    EXPECT_NE(r.out.find("voxel size:    (1, 1, 2.5)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("use:           density (--grid density, the default)"), std::string::npos) << r.out;
    for (const char* mode : {"hybrid", "reference"}) {
        r = run("render " + out + " -o " + path(std::string(mode) + ".png") + " --size 32x32 --spp 1 --mode " + mode);
        EXPECT_EQ(r.rc, 0) << r.err;
        EXPECT_TRUE(fs::exists(path(std::string(mode) + ".png")));
    }
}

TEST_F(CliVolume, ConvertRoundTrip) {
    const std::string raw = writeBytes("v.raw", 10 * 8 * 6);
    const std::string out = path("v.vdb");
    Result r = run("convert " + raw + " -o " + out + " --dims 10,8,6 --type uint8 --spacing 0.5,0.5,0.5");
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run("info " + out);
    EXPECT_NE(r.out.find("active voxels: 411"), std::string::npos) << r.out;  // 480 − ⌈480/7⌉ zeros
    EXPECT_NE(r.out.find("voxel size:    (0.5, 0.5, 0.5)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(0, 0, 0) .. (9, 7, 5)"), std::string::npos) << r.out;
}

TEST_F(CliVolume, ConvertBadInput) {
    const std::string raw = writeBytes("v.raw", 10 * 8 * 6);
    const std::string out = path("v.vdb");
    const std::string ok = " -o " + out + " --dims 10,8,6 --type uint8";
    expectError("convert " + path("missing.raw") + ok, path("missing.raw") + ": no such file", out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8,7 --type uint8", "needs 560 bytes", out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8,5 --type uint8", "has 480", out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8,6 --type uint16", raw, out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8 --type uint8", "--dims", out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8,x --type uint8", "--dims", out);
    expectError("convert " + raw + " -o " + out + " --dims 10,8,6 --type int8", "--type", out);
    expectError("convert " + raw + ok + " --spacing 1,1,0", "--spacing", out);
    expectError("convert " + raw + ok + " --threshold nan", "--threshold", out);
    expectError("convert " + raw + ok + " --threshold 2", "--threshold", out);  // nothing above it
    expectError("convert " + raw + " -o " + out + " --type uint8", "--dims", out);
    expectError("convert " + raw + " --dims 10,8,6 --type uint8", "-o");
}

TEST_F(CliVolume, InfoBadInput) {
    expectError("info " + path("missing.vdb"), path("missing.vdb") + ": no such file");
    std::ofstream(path("text.vdb")) << "hello\n";
    expectError("info " + path("text.vdb"), path("text.vdb"));
    ASSERT_EQ(run("generate sphere --res 20 -o " + path("s.vdb")).rc, 0);
    const std::string bytes = slurp(path("s.vdb"));
    for (size_t n : {size_t(9), size_t(60), size_t(128), bytes.size() / 2, bytes.size() - 1}) {
        std::ofstream(path("cut.vdb"), std::ios::binary).write(bytes.data(), std::streamsize(n));
        expectError("info " + path("cut.vdb"), path("cut.vdb"));
    }
    expectError("info", "FILE.vdb");
}

}  // namespace
