// tests/cli/test_cli_hostile.cpp — the hostile and careless inputs of issue 12, run through
// the real binary: each ends in one "vdbsplat: error: …" line naming the file or flag (or a
// correct result), exit 1, no output left behind, nothing clobbered, within seconds. Cases
// that hung or ran for minutes before the fix run under `timeout`, so a regression fails
// (exit 124) instead of stalling the suite. docs/robustness.md lists them all.
#include <gtest/gtest.h>
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern
#include <zlib.h>

#include <climits>
#include <filesystem>
#include <string>

#include <sys/stat.h>

#include "image/image.h"
#include "support/cli.h"
#include "volume/generate.h"
#include "volume/grid.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::slurp;
using test::spit;

class CliHostile : public ::testing::Test {
protected:
    static void SetUpTestSuite() { initOpenVdb(); }

    std::string path(const std::string& name) const { return scratch_.path(name); }
    std::string q(const std::string& name) const { return "'" + path(name) + "'"; }

    /// `vdbsplat ARGS` killed after @p seconds (exit 124 then: the bound was not kept).
    CliResult run(const std::string& args, int seconds = 60) const {
        return test::runVdbsplat(args, scratch_.dir(), seconds);
    }

    void expectError(const CliResult& r, const std::string& needle) const {
        EXPECT_EQ(r.rc, 1) << r.err;
        test::expectOneLineError(r, needle);
        test::expectNoTemporaries(scratch_.dir());
    }

    /// A small sphere grid written as @p name.
    std::string sphere(const std::string& name, int res = 12) const {
        GenerateOptions o;
        o.kind = "sphere";
        o.res = res;
        writeVolume(path(name), generateVolume(o));
        return path(name);
    }

    /// A float grid with the given active voxels (value 1) written as @p name.
    std::string voxels(const std::string& name, const std::vector<openvdb::Coord>& at) const {
        auto grid = openvdb::FloatGrid::create(0.0f);
        grid->setName("density");
        for (const auto& c : at) grid->tree().setValueOn(c, 1.0f);
        openvdb::io::File(path(name)).write({grid});
        return path(name);
    }

    test::ScratchDir scratch_{"hostile"};
};

/// gzip of @p bytes (one member), as `gzip` writes it.
std::string gzipped(const std::string& bytes) {
    z_stream s{};
    EXPECT_EQ(deflateInit2(&s, 9, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&s, uLong(bytes.size())), '\0');
    s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    s.avail_in = uInt(bytes.size());
    s.next_out = reinterpret_cast<Bytef*>(out.data());
    s.avail_out = uInt(out.size());
    EXPECT_EQ(deflate(&s, Z_FINISH), Z_STREAM_END);
    out.resize(s.total_out);
    deflateEnd(&s);
    return out;
}

/// A PNG whose header claims @p w × @p h pixels, with one empty IDAT chunk (a few dozen bytes).
std::string pngHeaderOnly(uint32_t w, uint32_t h) {
    const auto be32 = [](uint32_t v) {
        return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
    };
    const auto chunk = [&](const std::string& type, const std::string& data) {
        const std::string td = type + data;
        return be32(uint32_t(data.size())) + td +
               be32(uint32_t(crc32(0, reinterpret_cast<const Bytef*>(td.data()), uInt(td.size()))));
    };
    const std::string ihdr = be32(w) + be32(h) + std::string{8, 2, 0, 0, 0};  // 8-bit RGB
    return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", "") + chunk("IEND", "");
}

// --- compare ---------------------------------------------------------------------------

// OpenImageIO (the image library before libpng and OpenEXR) opened a .vdb named .png as a 33³
// volume image: readImage wrote past its buffer.
TEST_F(CliHostile, CompareRefusesAVolumeImage) {
    writeImage(path("a.png"), Image(33, 33));
    fs::copy_file(sphere("s.vdb", 33), path("b.png"));
    expectError(run("compare " + q("a.png") + " " + q("b.png")), "b.png");
    const CliResult r = run("compare " + q("b.png") + " " + q("a.png"));
    expectError(r, "volume image");
}

// A 20000² PNG header: refused from its size before any pixel is decoded (it needed > 8 GB).
TEST_F(CliHostile, CompareRefusesAHugeImageBeforeReadingIt) {
    writeImage(path("a.png"), Image(4, 4));
    spit(path("huge.png"), pngHeaderOnly(20000, 20000));
    const CliResult r = run("compare " + q("huge.png") + " " + q("a.png"), 30);
    expectError(r, "huge.png");
    EXPECT_NE(r.err.find("20000x20000"), std::string::npos) << r.err;
}

// A truncated PNG: libpng's own "libpng error: …" line must not precede vdbsplat's.
TEST_F(CliHostile, CompareOfATruncatedPngPrintsOneLine) {
    Image img(64, 64);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = glm::vec4(float(i % 7) / 7.f, 0.5f, 0.2f, 1.f);
    writeImage(path("a.png"), img);
    const std::string bytes = slurp(path("a.png"));
    spit(path("cut.png"), bytes.substr(0, bytes.size() * 2 / 3));
    expectError(run("compare " + q("cut.png") + " " + q("a.png")), "cut.png");
}

// --- render ------------------------------------------------------------------------------

// A transfer function nested 100 000 levels deep overflowed the stack (SIGSEGV).
TEST_F(CliHostile, DeeplyNestedTransferFunctionIsOneLine) {
    const std::string in = sphere("s.vdb");
    spit(path("deep.json"), "{\"color\": " + std::string(100000, '[') + std::string(100000, ']') + "}");
    expectError(run("render '" + in + "' -o " + q("o.png") + " --tf " + q("deep.json")), "nested deeper");
    EXPECT_FALSE(fs::exists(path("o.png")));
}

// --eye 1e15,0,0 was accepted and the stream spun for minutes.
TEST_F(CliHostile, FarEyeIsRefusedAtValidation) {
    const std::string in = sphere("s.vdb");
    const CliResult r = run("render '" + in + "' -o " + q("o.png") + " --eye 1e15,0,0", 30);
    expectError(r, "--eye");
    EXPECT_FALSE(fs::exists(path("o.png")));
    // Far but within 10^6 diagonals still renders.
    const CliResult ok = run("render '" + in + "' -o " + q("o.png") + " --eye 1e5,0,0 --size 32x32", 60);
    EXPECT_EQ(ok.rc, 0) << ok.err;
}

// Two voxels 3·10⁶ apart on the diagonal: the reference walked the empty bounding box
// (every ray millions of slices: many minutes); now it skips empty space, so the time
// follows the active voxels.
TEST_F(CliHostile, ReferenceSkipsEmptySpace) {
    const std::string in = voxels("far.vdb", {openvdb::Coord(0, 0, 0), openvdb::Coord(3000000, 3000000, 3000000)});
    const CliResult r = run("render '" + in + "' -o " + q("o.exr") + " --mode reference --size 64x64 --spp 1", 60);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("o.exr")));
}

// Voxels at the coordinate limit: `++ib` overflowed at INT_MAX (undefined, in practice a
// loop over 2^32 values).
TEST_F(CliHostile, ReferenceAtTheCoordinateLimit) {
    std::vector<openvdb::Coord> at;
    for (int d = 0; d < 3; ++d)
        for (int e = 0; e < 3; ++e) at.push_back(openvdb::Coord(INT_MAX - d, INT_MAX - e, INT_MAX - (d + e) % 3));
    const std::string in = voxels("edge.vdb", at);
    const CliResult r = run("render '" + in + "' -o " + q("o.exr") + " --mode reference --size 16x16 --spp 1", 60);
    ASSERT_EQ(r.rc, 0) << r.err;
    const Image img = readImage(path("o.exr"));
    float alpha = 0.f;
    for (const auto& p : img.pixels) alpha = std::max(alpha, p.w);
    EXPECT_GT(alpha, 0.f);
}

// A tables folder whose footprint.table is a FIFO hung; a link to /dev/zero read until
// memory ran out.
TEST_F(CliHostile, TablesThatAreNotRegularFilesAreRefused) {
    const std::string in = sphere("s.vdb");
    fs::create_directories(path("fifo"));
    ASSERT_EQ(::mkfifo(path("fifo/footprint.table").c_str(), 0644), 0);
    expectError(run("render '" + in + "' -o " + q("o.png") + " --tables " + q("fifo"), 30), "footprint.table");
    fs::create_directories(path("zero"));
    fs::create_symlink("/dev/zero", path("zero/footprint.table"));
    expectError(run("render '" + in + "' -o " + q("o.png") + " --tables " + q("zero"), 30), "not a regular file");
    EXPECT_FALSE(fs::exists(path("o.png")));
}

// An 8 KB file of active tiles holding 2·10⁹ voxels ran for more than 10 minutes.
TEST_F(CliHostile, ActiveTileVoxelsAreBoundedBeforeWork) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    // 10³ tiles of 128³ voxels: 2.1·10⁹ voxels in a file of a few KB.
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(1279, 1279, 1279)), 0.5f, true);
    ASSERT_GT(grid->activeVoxelCount(), 2'000'000'000u);
    openvdb::io::File(path("tiles.vdb")).write({grid});
    const CliResult r = run("render " + q("tiles.vdb") + " -o " + q("o.png") + " --size 32x32", 30);
    expectError(r, "--max-voxels");
    EXPECT_NE(r.err.find("tiles.vdb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("o.png")));
    // The flag raises the bound; beyond 2^32 it is refused as a flag error.
    expectError(run("render " + q("tiles.vdb") + " -o " + q("o.png") + " --max-voxels 5000000000"), "--max-voxels");
}

// --- convert -------------------------------------------------------------------------------

// 130 KB of gzip'd 0xFF became 1.3·10⁸ active voxels: X*Y*Z is bounded before reading.
TEST_F(CliHostile, ConvertBoundsTheVoxelCount) {
    spit(path("ff.raw.gz"), gzipped(std::string(1 << 20, '\xff')));
    const CliResult r = run("convert " + q("ff.raw.gz") + " -o " + q("o.vdb") + " --dims 512,512,512 --type uint8", 30);
    expectError(r, "--dims");
    EXPECT_NE(r.err.find("--max-voxels"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("o.vdb")));
    // Within the bound it converts.
    const CliResult ok = run("convert " + q("ff.raw.gz") + " -o " + q("o.vdb") + " --dims 128,128,64 --type uint8");
    EXPECT_EQ(ok.rc, 0) << ok.err;
}

TEST_F(CliHostile, ConvertRefusesTrailingGarbageAfterGzip) {
    spit(path("v.raw.gz"), gzipped(std::string(64, '\x40')) + "this is not gzip");
    expectError(run("convert " + q("v.raw.gz") + " -o " + q("o.vdb") + " --dims 4,4,4 --type uint8"),
                "trailing garbage");
    EXPECT_FALSE(fs::exists(path("o.vdb")));
}

TEST_F(CliHostile, ConvertSpacingOutOfRangeNamesTheFlag) {
    spit(path("v.raw"), std::string(8, '\x40'));
    for (const char* s : {"1e300,1e300,1e300", "1e-7,1e-7,1e-7"}) {
        expectError(run("convert " + q("v.raw") + " -o " + q("o.vdb") + " --dims 2,2,2 --type uint8 --spacing " + s),
                    "--spacing");
        EXPECT_FALSE(fs::exists(path("o.vdb"))) << s;
    }
}

// --- info, generate --------------------------------------------------------------------------

// Grid names reached the terminal raw: a file could send escape sequences.
TEST_F(CliHostile, InfoEscapesControlCharacters) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("evil\x1b]2;owned\x07\x1b[31mred\xc2\x9b" "2J");
    grid->tree().setValueOn(openvdb::Coord(0), 1.0f);
    openvdb::io::File(path("evil.vdb")).write({grid});
    const CliResult r = run("info " + q("evil.vdb"));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find('\x07'), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("\xc2\x9b"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("evil\\x1b]2;owned\\x07\\x1b[31mred\\xc2\\x9b2J"), std::string::npos) << r.out;
}

// The help said --res 2..4096 for every kind; sphere needs 3.
TEST_F(CliHostile, GenerateHelpAndValidationAgreeOnTheSphereRes) {
    const CliResult help = run("generate --help");
    ASSERT_EQ(help.rc, 0);
    EXPECT_NE(help.out.find("sphere: 3..4096"), std::string::npos) << help.out;
    expectError(run("generate sphere --res 2 -o " + q("s.vdb")), "[3, 4096]");
    EXPECT_EQ(run("generate sphere --res 3 -o " + q("s.vdb")).rc, 0);
}

// --- outputs: links and devices are never replaced ------------------------------------------

// -o, --stats and --json through a symbolic link write its target; the link stays a link.
TEST_F(CliHostile, OutputsWriteThroughSymbolicLinks) {
    const std::string in = sphere("s.vdb");
    fs::create_symlink("real.png", path("link.png"));
    fs::create_symlink("real.json", path("link.json"));
    fs::create_symlink("real.vdb", path("link.vdb"));
    fs::create_symlink("cmp.json", path("cmp-link.json"));
    CliResult r = run("render '" + in + "' -o " + q("link.png") + " --size 16x16 --stats " + q("link.json"));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run("generate sphere --res 8 -o " + q("link.vdb"));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run("compare " + q("real.png") + " " + q("real.png") + " --json " + q("cmp-link.json"));
    ASSERT_EQ(r.rc, 0) << r.err;
    for (const char* link : {"link.png", "link.json", "link.vdb", "cmp-link.json"})
        EXPECT_TRUE(fs::is_symlink(path(link))) << link << " was replaced";
    for (const char* real : {"real.png", "real.json", "real.vdb", "cmp.json"})
        EXPECT_TRUE(fs::is_regular_file(path(real))) << real;
    test::expectNoTemporaries(scratch_.dir());
}

// A device node or FIFO: text outputs stream into it, binary outputs refuse it; never replaced.
TEST_F(CliHostile, DevicesAndFifosAreNeverReplaced) {
    const std::string in = sphere("s.vdb");
    fs::create_symlink("/dev/null", path("null.json"));
    CliResult r = run("render '" + in + "' -o " + q("o.png") + " --size 16x16 --stats " + q("null.json"));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(fs::is_symlink(path("null.json")));
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
    // What /dev/stdout is (a link to /proc/self/fd/1), in the scratch folder: the stats
    // reach the process's stdout (a file here) and the link stays.
    fs::create_symlink("/proc/self/fd/1", path("stdout.json"));
    r = run("render '" + in + "' -o " + q("o.png") + " --size 16x16 --stats " + q("stdout.json"));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("\"active_voxels\""), std::string::npos) << r.out;
    EXPECT_TRUE(fs::is_symlink(path("stdout.json")));
    ASSERT_EQ(::mkfifo(path("fifo.png").c_str(), 0644), 0);
    ASSERT_EQ(::mkfifo(path("fifo.vdb").c_str(), 0644), 0);
    expectError(run("render '" + in + "' -o " + q("fifo.png") + " --size 16x16", 30), "fifo.png");
    expectError(run("generate sphere --res 8 -o " + q("fifo.vdb"), 30), "fifo.vdb");
    EXPECT_TRUE(fs::is_fifo(path("fifo.png")));
    EXPECT_TRUE(fs::is_fifo(path("fifo.vdb")));
    // A FIFO nobody reads: an error, not a hang.
    ASSERT_EQ(::mkfifo(path("fifo.json").c_str(), 0644), 0);
    expectError(run("compare " + q("o.png") + " " + q("o.png") + " --json " + q("fifo.json"), 30), "fifo.json");
    EXPECT_TRUE(fs::is_fifo(path("fifo.json")));
}

// A full disk (here: the file-size limit) is reported against the output, not the temporary.
TEST_F(CliHostile, WriteFailureNamesTheOutputNotTheTemporary) {
    const std::string in = sphere("s.vdb");
    for (const std::string& cmd : {"generate sphere --res 64 -o " + q("big.vdb"),
                                   "render '" + in + "' -o " + q("big.exr") + " --size 256x256"}) {
        const CliResult r = test::runVdbsplat(cmd, scratch_.dir(), 60, "ulimit -f 8; trap '' XFSZ; ");
        expectError(r, "big.");
        EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << r.err;
    }
    EXPECT_FALSE(fs::exists(path("big.vdb")));
    EXPECT_FALSE(fs::exists(path("big.exr")));
}

}  // namespace
}  // namespace vdbsplat

namespace vdbsplat {
namespace {

// An output flag naming the command's own input replaced it: `render IN.vdb --stats IN.vdb`
// and `bench IN.vdb --json IN.vdb` overwrote the volume with JSON. Every output is now checked
// against the inputs (same file through any path or link) before any work.
TEST_F(CliHostile, OutputsNeverReplaceTheInput) {
    const std::string in = sphere("s.vdb");
    const std::string before = slurp(in);
    fs::create_hard_link(in, path("hard.vdb"));
    expectError(run("render '" + in + "' -o " + q("o.png") + " --stats '" + in + "'"), "--stats");
    expectError(run("render '" + in + "' -o " + q("o.png") + " --stats " + q("hard.vdb")), "is the input file");
    EXPECT_FALSE(fs::exists(path("o.png")));
    expectError(run("bench '" + in + "' --runs 1 --warmup 0 --distances 8 --modes point --json '" + in + "'"), "--json");
    Image img(8, 8);
    writeImage(path("a.png"), img);
    const std::string image = slurp(path("a.png"));
    expectError(run("compare " + q("a.png") + " " + q("a.png") + " --json " + q("a.png")), "--json");
    EXPECT_EQ(slurp(path("a.png")), image);
    spit(path("raw.bin"), std::string(8, '\x01'));
    expectError(run("convert " + q("raw.bin") + " -o " + q("raw.bin") + " --dims 2,2,2 --type uint8"), "-o");
    EXPECT_EQ(slurp(path("raw.bin")), std::string(8, '\x01'));
    EXPECT_EQ(slurp(in), before);
}

}  // namespace
}  // namespace vdbsplat
