// tests/volume/test_nrrd.cpp — the NRRD reader (volume/nrrd.h): files written by Teem's unu
// (attached and detached, raw and gzip, little and big endian, space directions and spacings)
// convert to exactly the raw oracle's voxels with the header's spacing and origin kept; every
// bad header or data ends in an Error naming the file and the field.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>

#include "support/error_of.h"
#include "support/readers.h"
#include "util/error.h"
#include "volume/nrrd.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::errorOf;
using test::expectSameVoxels;
using test::fixture;
using test::rawOracle;
using test::worldOf;

openvdb::FloatGrid::Ptr nrrd(const std::string& path, double threshold = 0.0) {
    ConvertOptions o;
    o.threshold = threshold;
    return convertNrrd(path, o);
}

TEST(NrrdFromTeem, AttachedRawAndGzipMatchRawForEveryType) {
    for (const std::string kind : {"u8", "u16", "i16", "f32"}) {  // i16 is written big-endian
        for (const std::string enc : {"raw", "gzip"}) {
            const std::string name = kind + "_" + enc + ".nrrd";
            expectSameVoxels(*rawOracle(kind), *nrrd(fixture(name)), name);
            expectSameVoxels(*rawOracle(kind, 0.3), *nrrd(fixture(name), 0.3), name + " threshold 0.3");
        }
    }
}

TEST(NrrdFromTeem, DetachedRawAndGzipMatchRaw) {
    expectSameVoxels(*rawOracle("u16"), *nrrd(fixture("u16_detached.nhdr")), "u16_detached.nhdr");
    expectSameVoxels(*rawOracle("u16"), *nrrd(fixture("u16_detached_gz.nhdr")), "u16_detached_gz.nhdr");
}

TEST(NrrdFromTeem, TransformKeepsSpaceDirectionsAndOrigin) {
    const auto grid = nrrd(fixture("u16_gzip.nrrd"));  // origin (-1,2,3.5), directions 0.5, 0.5, 1.25
    const openvdb::Vec3d o = worldOf(*grid, {0, 0, 0}), p = worldOf(*grid, {1, 1, 1}), q = worldOf(*grid, {6, 4, 3});
    EXPECT_NEAR(o.x(), -1.0, 1e-12);
    EXPECT_NEAR(o.y(), 2.0, 1e-12);
    EXPECT_NEAR(o.z(), 3.5, 1e-12);
    EXPECT_NEAR(p.x(), -0.5, 1e-12);
    EXPECT_NEAR(p.y(), 2.5, 1e-12);
    EXPECT_NEAR(p.z(), 4.75, 1e-12);
    EXPECT_NEAR(q.z(), 3.5 + 3 * 1.25, 1e-12);
}

TEST(NrrdFromTeem, SpacingsWithoutSpaceGiveAScaleAtTheOrigin) {
    const auto grid = nrrd(fixture("u8_spacings.nrrd"));
    expectSameVoxels(*rawOracle("u8"), *grid, "u8_spacings.nrrd");
    const openvdb::Vec3d p = worldOf(*grid, {2, 2, 2});
    EXPECT_NEAR(p.x(), 1.0, 1e-12);
    EXPECT_NEAR(p.y(), 1.0, 1e-12);
    EXPECT_NEAR(p.z(), 2.5, 1e-12);
}

TEST(NrrdFromTeem, HeaderFieldsAreRead) {
    const NrrdHeader h = readNrrdHeader(fixture("i16_raw.nrrd"));
    EXPECT_EQ(h.layout.dims, (std::array<int, 3>{7, 5, 4}));
    EXPECT_EQ(h.layout.type, RawType::Int16);
    EXPECT_TRUE(h.layout.bigEndian);
    EXPECT_EQ(h.source.path, fixture("i16_raw.nrrd"));
    EXPECT_EQ(h.source.offset + 280, fs::file_size(fixture("i16_raw.nrrd")));  // attached: the data ends the file
    const NrrdHeader d = readNrrdHeader(fixture("u16_detached_gz.nhdr"));
    EXPECT_EQ(d.source.path, fixture("u16_detached_gz.raw.gz"));
    EXPECT_EQ(d.source.encoding, VoxelSource::Encoding::Gzip);
}

// --- Hand-written headers: the forms of Teem's format definition, and what must be refused ---

class NrrdBad : public ::testing::Test {
protected:
    void SetUp() override {
        char tmpl[] = "/tmp/vdbsplat_nrrd_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }

    /// A 4x4x4 uint8 volume of 64 ones after @p header (each line gets a '\n'; a blank line ends it).
    std::string write(const std::string& name, const std::string& header, const std::string& data = std::string(64, 1)) {
        const std::string path = dir_ + "/" + name;
        std::ofstream(path, std::ios::binary) << header << "\n" << data;
        return path;
    }
    /// Expects an Error that names the file and contains @p needle.
    void expectError(const std::string& path, const std::string& needle) {
        const std::string msg = errorOf([&] { nrrd(path); });
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << "wanted '" << needle << "' in: " << msg;
    }
    std::string dir_;
};

const std::string kHead = "NRRD0004\ntype: uchar\ndimension: 3\n";

TEST_F(NrrdBad, AGoodHandWrittenHeaderConverts) {  // the control for every case below
    const auto grid = nrrd(write("ok.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\n# a comment\nkey:=value\n"));
    EXPECT_EQ(grid->activeVoxelCount(), 64u);
    EXPECT_FLOAT_EQ(grid->tree().getValue(openvdb::Coord(3, 3, 3)), 1.0f / 255.0f);
}

TEST_F(NrrdBad, MissingOrMalformedFields) {
    expectError(write("a.nrrd", "NRRD0004\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n"), "type: missing");
    expectError(write("b.nrrd", kHead + "encoding: raw\n"), "sizes: missing");
    expectError(write("c.nrrd", kHead + "sizes: 4 4 4\n"), "encoding: missing");
    expectError(write("d.nrrd", "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 4 16\nencoding: raw\n"), "dimension");
    expectError(write("e.nrrd", kHead + "sizes: 4 4\nencoding: raw\n"), "sizes: expected 3 sizes");
    expectError(write("f.nrrd", kHead + "sizes: 4 x 4\nencoding: raw\n"), "sizes");
    expectError(write("g.nrrd", kHead + "sizes: 4 4 0\nencoding: raw\n"), "sizes");
    expectError(write("h.nrrd", "PNG\ntype: uchar\n"), "not a NRRD file");
    expectError(write("i.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\nbogus field: 1\n"), "bogus field: unknown field");
    expectError(write("j.nrrd", kHead + "sizes: 4 4 4\nsizes: 4 4 4\nencoding: raw\n"), "sizes: given twice");
    expectError(write("k.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\nno separator\n"), "not 'field: value'");
}

TEST_F(NrrdBad, UnsupportedTypeEncodingAndEndian) {
    expectError(write("a.nrrd", "NRRD0004\ntype: int\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n"),
                "type: unsupported type 'int'");
    expectError(write("b.nrrd", kHead + "sizes: 4 4 4\nencoding: bzip2\n"), "encoding: unsupported encoding 'bzip2'");
    expectError(write("c.nrrd", kHead + "sizes: 4 4 4\nencoding: ascii\n"), "encoding: unsupported");
    expectError(write("d.nrrd", "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 4 4 2\nencoding: raw\n"),
                "endian: missing");
    expectError(write("e.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\nendian: middle\n"), "endian: expected little or big");
    expectError(write("f.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\nline skip: 2\n"), "line skip");
    expectError(write("g.nrrd", kHead + "sizes: 4 4 4\nencoding: gzip\nbyte skip: -1\n"), "byte skip");
}

TEST_F(NrrdBad, SizesThatDoNotMatchTheData) {
    expectError(write("short.nrrd", kHead + "sizes: 4 4 5\nencoding: raw\n"), "sizes 4 4 5 of uint8 needs 80 bytes");
    expectError(write("long.nrrd", kHead + "sizes: 4 4 3\nencoding: raw\n"), "has 64");
    std::string gz(200, '\0');
    uLongf n = gz.size();
    const std::string data(64, 1);
    ASSERT_EQ(compress2(reinterpret_cast<Bytef*>(gz.data()), &n, reinterpret_cast<const Bytef*>(data.data()), 64, 9), Z_OK);
    // NRRD's gzip is the gzip format; a zlib stream is corrupt gzip data.
    expectError(write("zlib.nrrd", kHead + "sizes: 4 4 4\nencoding: gzip\n", gz.substr(0, n)), "corrupt gzip");
    expectError(write("plain.nrrd", kHead + "sizes: 4 4 4\nencoding: gzip\n"), "gzip");
}

TEST_F(NrrdBad, AbsurdSizesAreRefusedBeforeReading) {
    expectError(write("big.nrrd", kHead + "sizes: 65536 65536 65536\nencoding: raw\n"), "sizes: 65536,65536,65536");
    expectError(write("big2.nrrd", kHead + "sizes: 65536 65536 65536\nencoding: raw\n"), "--max-voxels");
    expectError(write("huge.nrrd", kHead + "sizes: 4 4 99999999999\nencoding: raw\n"), "sizes");
    std::string header = "NRRD0004\n";
    for (int i = 0; i < 40000; ++i) header += "# a comment line to make the header longer than a megabyte\n";
    expectError(write("long-header.nrrd", header), "header is longer than");
}

TEST_F(NrrdBad, GeometryFields) {
    const std::string base = kHead + "sizes: 4 4 4\nencoding: raw\n";
    expectError(write("a.nrrd", base + "space: RAS\nspace directions: (1,0,0) (2,0,0) (0,0,1)\n"),
                "space directions: the axes are singular");
    expectError(write("b.nrrd", base + "spacings: 1 0 1\n"), "spacings: voxel size 0 along axis 1");
    expectError(write("c.nrrd", base + "spacings: 1 1e-9 1\n"), "spacings");
    expectError(write("d.nrrd", base + "space directions: (1,0,0) (0,1,0) (0,0,1)\n"), "needs a space");
    expectError(write("e.nrrd", base + "space: RAS\n"), "space directions: missing");
    expectError(write("f.nrrd", base + "space: RAS\nspace directions: (1,0,0) (0,1,0)\n"), "space directions: expected 3");
    expectError(write("g.nrrd", base + "space: RAS\nspace directions: (1,0,0) (0,1,0) none\n"), "space directions");
    expectError(write("h.nrrd", base + "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (1,2)\n"),
                "space origin");
    expectError(write("i.nrrd", base + "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (1e300,0,0)\n"),
                "space origin");
    expectError(write("j.nrrd", base + "space: RAS-time\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"), "space");
    expectError(write("k.nrrd", base + "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspacings: 1 1 1\n"),
                "spacings: given together");
}

TEST_F(NrrdBad, DetachedDataAndByteSkip) {
    std::ofstream(dir_ + "/data.raw", std::ios::binary) << std::string(64, 2);
    const std::string det = kHead + "sizes: 4 4 4\nencoding: raw\n";
    EXPECT_EQ(nrrd(write("ok.nhdr", det + "data file: data.raw", ""))->activeVoxelCount(), 64u);
    expectError(write("missing.nhdr", det + "data file: nope.raw", ""), "data file");
    expectError(write("missing2.nhdr", det + "data file: nope.raw", ""), "no such file");
    expectError(write("list.nhdr", det + "data file: LIST\n"), "data file: only one data file");
    expectError(write("dev.nhdr", det + "data file: /dev/zero", ""), "not a regular file");
    expectError(write("nodata.nhdr", det.substr(0, det.size() - 1), ""), "data file: missing");
    // byte skip: 10 junk bytes before the voxels (attached); -1: the voxels end the file.
    const auto skipped = nrrd(write("skip.nrrd", kHead + "sizes: 4 4 4\nencoding: raw\nbyte skip: 10\n",
                                    std::string(10, 9) + std::string(64, 1)));
    EXPECT_EQ(skipped->activeVoxelCount(), 64u);
    EXPECT_FLOAT_EQ(skipped->tree().getValue(openvdb::Coord(0, 0, 0)), 1.0f / 255.0f);
    std::ofstream(dir_ + "/end.raw", std::ios::binary) << std::string(5, 9) << std::string(64, 3);
    const auto atEnd = nrrd(write("end.nhdr", det + "byte skip: -1\ndata file: end.raw", ""));
    EXPECT_EQ(atEnd->activeVoxelCount(), 64u);
    EXPECT_FLOAT_EQ(atEnd->tree().getValue(openvdb::Coord(0, 0, 0)), 3.0f / 255.0f);
}

}  // namespace
}  // namespace vdbsplat
