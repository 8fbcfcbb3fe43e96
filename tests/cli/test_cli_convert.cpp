// tests/cli/test_cli_convert.cpp — `vdbsplat convert` on NRRD and VTI run as the real binary:
// the format follows the extension, the same volume as raw, .nrrd, .nhdr and .vti gives the same
// grid (compared through `info`), raw-only flags are refused for header formats, and every bad
// file ends in one "vdbsplat: error:" line naming the file and field, exit 1, no output left.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/cli.h"
#include "support/readers.h"

namespace {

namespace fs = std::filesystem;
using Result = vdbsplat::test::CliResult;
using vdbsplat::test::fixture;

class CliConvert : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }
    Result run(const std::string& args) const { return vdbsplat::test::runVdbsplat(args, scratch_.dir()); }

    void expectError(const std::string& args, const std::string& needle, const std::string& output) const {
        const Result r = run(args);
        EXPECT_EQ(r.rc, 1) << args;
        vdbsplat::test::expectOneLineError(r, needle, args);
        EXPECT_FALSE(fs::exists(output)) << args;
        vdbsplat::test::expectNoTemporaries(scratch_.dir());
    }
    /// The lines of `info` about a converted grid's voxels (count, index box, values), not its transform.
    std::string voxelsOf(const std::string& vdb) const {
        const Result r = run("info " + vdb);
        EXPECT_EQ(r.rc, 0) << r.err;
        std::istringstream in(r.out);
        std::string out;
        for (std::string line; std::getline(in, line);)
            if (line.find("active voxels:") != line.npos || line.find("index bbox:") != line.npos ||
                line.find("value") != line.npos)
                out += line + "\n";
        return out;
    }
    std::string voxelSizeOf(const std::string& vdb) const {
        const std::string out = run("info " + vdb).out;
        const size_t at = out.find("voxel size:");
        return at == out.npos ? "" : out.substr(at, out.find('\n', at) - at);
    }

    vdbsplat::test::ScratchDir scratch_{"cli-convert"};
};

TEST_F(CliConvert, RawNrrdAndVtiGiveTheSameGrid) {
    const std::string raw = path("raw.vdb");
    Result r = run("convert " + fixture("vol_u16.raw") + " -o " + raw + " --dims 7,5,4 --type uint16 --threshold 0.2");
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::string expected = voxelsOf(raw);
    EXPECT_NE(expected.find("active voxels"), std::string::npos) << expected;
    EXPECT_NE(expected.find("index bbox"), std::string::npos) << expected;
    for (const std::string in : {"u16_raw.nrrd", "u16_gzip.nrrd", "u16_detached_gz.nhdr", "u16_ascii.vti",
                                  "u16_appended_zlib_h64.vti", "u16_binary_none_h32.vti"}) {
        const std::string out = path(in + ".vdb");
        r = run("convert " + fixture(in) + " -o " + out + " --threshold 0.2");
        ASSERT_EQ(r.rc, 0) << in << ": " << r.err;
        EXPECT_NE(r.out.find("active voxels of 140"), std::string::npos) << r.out;
        EXPECT_EQ(voxelsOf(out), expected) << in;
        const bool nrrd = in.find(".n") != std::string::npos;  // Teem's files: spacing 0.5, 0.5, 1.25
        EXPECT_EQ(voxelSizeOf(out), nrrd ? "voxel size:    (0.5, 0.5, 1.25)" : "voxel size:    (1, 1, 1)") << in;
    }
}

TEST_F(CliConvert, HeaderFormatsRefuseRawFlagsAndRawRefusesArray) {
    const std::string out = path("o.vdb");
    expectError("convert " + fixture("u8_raw.nrrd") + " -o " + out + " --dims 7,5,4", "--dims: conflicts with the header", out);
    expectError("convert " + fixture("u8_ascii.vti") + " -o " + out + " --type uint8", "--type: conflicts", out);
    expectError("convert " + fixture("u8_ascii.vti") + " -o " + out + " --spacing 1,1,1", "--spacing: conflicts", out);
    expectError("convert " + fixture("u8_raw.nrrd") + " -o " + out + " --array density", "--array: only for .vti", out);
    expectError("convert " + fixture("vol_u8.raw") + " -o " + out + " --dims 7,5,4 --type uint8 --array d",
                "--array: only for .vti", out);
    expectError("convert " + fixture("u8_two_arrays.vti") + " -o " + out + " --array nope", "no DataArray named 'nope'", out);
    const Result ok = run("convert " + fixture("u8_two_arrays.vti") + " -o " + out + " --array density");
    EXPECT_EQ(ok.rc, 0) << ok.err;
}

TEST_F(CliConvert, BadFilesEndInOneErrorLine) {
    const std::string out = path("o.vdb");
    const std::string nrrd = path("bad.nrrd");
    std::ofstream(nrrd, std::ios::binary) << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 5\nencoding: raw\n\n"
                                          << std::string(64, 1);
    expectError("convert " + nrrd + " -o " + out, nrrd + ": size mismatch: sizes 4 4 5", out);
    std::ofstream(nrrd, std::ios::binary) << "NRRD0004\ntype: int\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n";
    expectError("convert " + nrrd + " -o " + out, nrrd + ": type: unsupported type 'int'", out);
    const std::string vti = path("bad.vti");
    std::ofstream(vti, std::ios::binary) << "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 65535 0 65535 0 65535\">"
                                         << "<Piece Extent=\"0 65535 0 65535 0 65535\"/></ImageData></VTKFile>";
    expectError("convert " + vti + " -o " + out, vti + ": ImageData WholeExtent", out);
    std::ofstream(vti, std::ios::binary) << "not xml at all";
    expectError("convert " + vti + " -o " + out, vti + ": malformed XML", out);
    // An existing output survives a failed conversion untouched.
    std::ofstream(out) << "keep";
    const Result r = run("convert " + nrrd + " -o " + out);
    EXPECT_EQ(r.rc, 1);
    EXPECT_EQ(vdbsplat::test::slurp(out), "keep");
}

}  // namespace
