// tests/volume/test_raw.cpp — raw volume conversion (volume/raw.h): layout (x fastest),
// normalisation per type, little-endian decoding, threshold, .gz and plain files, exact
// size checks (too short, too long, truncated gzip), flag parsing, and the real Engine
// and Bonsai volumes from ../shared/volumes (skipped when absent).
#include <gtest/gtest.h>
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "util/error.h"
#include "volume/grid.h"
#include "volume/raw.h"
#include "support/error_of.h"

namespace vdbsplat {
namespace {

using test::errorOf;

namespace fs = std::filesystem;
using Bytes = std::vector<unsigned char>;
using openvdb::Coord;

class Raw : public ::testing::Test {
protected:
    void SetUp() override {
        char tmpl[] = "/tmp/vdbsplat_raw_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::string writePlain(const std::string& name, const Bytes& data) {
        const std::string path = dir_ + "/" + name;
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data.data()), data.size());
        return path;
    }
    std::string writeGz(const std::string& name, const Bytes& data) {
        const std::string path = dir_ + "/" + name;
        gzFile f = gzopen(path.c_str(), "wb");
        EXPECT_EQ(gzwrite(f, data.data(), unsigned(data.size())), int(data.size()));
        gzclose(f);
        return path;
    }
    std::string dir_;
};

Bytes pattern8(int n) {
    Bytes b(n);
    for (int i = 0; i < n; ++i) b[i] = static_cast<unsigned char>((i * 37) % 256);
    return b;
}

RawSpec spec(int x, int y, int z, RawType type, double threshold = 0.0) {
    RawSpec s;
    s.dims = {x, y, z};
    s.type = type;
    s.threshold = threshold;
    return s;
}

TEST_F(Raw, Uint8LayoutIsXFastestAndNormalised) {
    const int X = 5, Y = 4, Z = 3;
    const Bytes data = pattern8(X * Y * Z);
    RawStats stats;
    auto grid = convertRaw(writePlain("a.raw", data), spec(X, Y, Z, RawType::UInt8), &stats);
    uint64_t nonzero = 0;
    auto acc = grid->getConstAccessor();
    for (int z = 0; z < Z; ++z)
        for (int y = 0; y < Y; ++y)
            for (int x = 0; x < X; ++x) {
                const unsigned char v = data[x + X * (y + Y * z)];
                nonzero += v > 0;
                ASSERT_EQ(acc.isValueOn(Coord(x, y, z)), v > 0) << x << "," << y << "," << z;
                if (v) {
                    ASSERT_FLOAT_EQ(acc.getValue(Coord(x, y, z)), v / 255.0f);
                }
            }
    EXPECT_EQ(grid->activeVoxelCount(), nonzero);
    EXPECT_EQ(stats.active, nonzero);
    EXPECT_EQ(stats.bytes, uint64_t(X * Y * Z));
    EXPECT_LT(nonzero, uint64_t(X * Y * Z));  // the pattern has zeros, which stay inactive
    EXPECT_EQ(grid->getName(), "density");
}

TEST_F(Raw, GzipAndPlainGiveTheSameGrid) {
    const Bytes data = pattern8(17 * 9 * 11);
    auto a = convertRaw(writePlain("a.raw", data), spec(17, 9, 11, RawType::UInt8));
    auto b = convertRaw(writeGz("a.raw.gz", data), spec(17, 9, 11, RawType::UInt8));
    ASSERT_EQ(a->activeVoxelCount(), b->activeVoxelCount());
    auto acc = b->getConstAccessor();
    for (auto it = a->cbeginValueOn(); it; ++it) ASSERT_EQ(acc.getValue(it.getCoord()), *it);
}

TEST_F(Raw, Uint16IsLittleEndianOver65535) {
    const Bytes data{0x00, 0x01, 0xff, 0xff, 0x00, 0x00, 0x01, 0x00};  // 256, 65535, 0, 1
    auto grid = convertRaw(writeGz("b.raw.gz", data), spec(4, 1, 1, RawType::UInt16));
    auto acc = grid->getConstAccessor();
    EXPECT_FLOAT_EQ(acc.getValue(Coord(0, 0, 0)), 256.0f / 65535.0f);
    EXPECT_FLOAT_EQ(acc.getValue(Coord(1, 0, 0)), 1.0f);
    EXPECT_FALSE(acc.isValueOn(Coord(2, 0, 0)));
    EXPECT_FLOAT_EQ(acc.getValue(Coord(3, 0, 0)), 1.0f / 65535.0f);
    EXPECT_EQ(grid->activeVoxelCount(), 3u);
}

TEST_F(Raw, Float32KeepsValuesAndLeavesNonFiniteInactive) {
    const std::vector<float> values{0.25f, -1.0f, NAN, INFINITY, 7.5f, 0.0f};
    Bytes data;
    for (float v : values) {
        const uint32_t bits = std::bit_cast<uint32_t>(v);
        for (int k = 0; k < 4; ++k) data.push_back(static_cast<unsigned char>(bits >> (8 * k)));
    }
    RawStats stats;
    auto grid = convertRaw(writePlain("f.raw", data), spec(3, 2, 1, RawType::Float32), &stats);
    auto acc = grid->getConstAccessor();
    EXPECT_EQ(stats.nonFinite, 2u);
    EXPECT_EQ(grid->activeVoxelCount(), 2u);
    EXPECT_EQ(acc.getValue(Coord(0, 0, 0)), 0.25f);
    EXPECT_EQ(acc.getValue(Coord(1, 1, 0)), 7.5f);  // index 4 = (1, 1, 0)
    EXPECT_FALSE(acc.isValueOn(Coord(1, 0, 0)));  // negative: not above the default threshold 0
    EXPECT_FALSE(acc.isValueOn(Coord(2, 0, 0)));  // NaN
    EXPECT_FALSE(acc.isValueOn(Coord(0, 1, 0)));  // inf
}

TEST_F(Raw, ThresholdIsStrictAndInNormalisedUnits) {
    Bytes data(256);
    for (int i = 0; i < 256; ++i) data[i] = static_cast<unsigned char>(i);
    const std::string path = writePlain("ramp.raw", data);
    EXPECT_EQ(convertRaw(path, spec(16, 16, 1, RawType::UInt8, 0.5))->activeVoxelCount(), 128u);  // 128..255
    EXPECT_EQ(convertRaw(path, spec(16, 16, 1, RawType::UInt8, 30 / 255.0))->activeVoxelCount(), 225u);  // 31..255
    EXPECT_EQ(convertRaw(path, spec(16, 16, 1, RawType::UInt8, -1.0))->activeVoxelCount(), 256u);
    EXPECT_EQ(convertRaw(path, spec(16, 16, 1, RawType::UInt8, 1.0))->activeVoxelCount(), 0u);
}

TEST_F(Raw, SpacingSetsAUniformTransform) {
    RawSpec s = spec(4, 4, 4, RawType::UInt8);
    s.spacing = {0.5, 0.5, 0.5};
    Volume v = makeVolume(convertRaw(writePlain("s.raw", Bytes(64, 200)), s));
    EXPECT_DOUBLE_EQ(v.voxelSize, 0.5);
    const glm::dvec4 w = v.indexToWorld * glm::dvec4(2, 3, 1, 1);
    EXPECT_DOUBLE_EQ(w.x, 1.0);
    EXPECT_DOUBLE_EQ(w.y, 1.5);
    EXPECT_DOUBLE_EQ(w.z, 0.5);
}

TEST_F(Raw, SizeMismatchNamesFileAndByteCounts) {
    const Bytes data = pattern8(100);
    for (const std::string& path : {writePlain("m.raw", data), writeGz("m.raw.gz", data)}) {
        std::string short_ = errorOf([&] { convertRaw(path, spec(10, 10, 2, RawType::UInt8)); });
        EXPECT_NE(short_.find(path), std::string::npos) << short_;
        EXPECT_NE(short_.find("needs 200 bytes"), std::string::npos) << short_;
        EXPECT_NE(short_.find("100"), std::string::npos) << short_;
        std::string long_ = errorOf([&] { convertRaw(path, spec(9, 10, 1, RawType::UInt8)); });
        EXPECT_NE(long_.find("needs 90 bytes"), std::string::npos) << long_;
        EXPECT_NE(long_.find("has 100"), std::string::npos) << long_;
        std::string type = errorOf([&] { convertRaw(path, spec(10, 10, 1, RawType::UInt16)); });
        EXPECT_NE(type.find("needs 200 bytes"), std::string::npos) << type;
    }
}

TEST_F(Raw, TruncatedOrCorruptGzipIsAnError) {
    const Bytes data = pattern8(64 * 64 * 8);
    const std::string gz = writeGz("t.raw.gz", data);
    std::ifstream in(gz, std::ios::binary);
    Bytes compressed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    compressed.resize(compressed.size() / 2);
    const std::string cut = writePlain("cut.raw.gz", compressed);
    EXPECT_NE(errorOf([&] { convertRaw(cut, spec(64, 64, 8, RawType::UInt8)); }).find(cut), std::string::npos);
    Bytes garbage = compressed;
    for (size_t i = 20; i < garbage.size(); i += 7) garbage[i] ^= 0x5a;
    const std::string bad = writePlain("bad.raw.gz", garbage);
    EXPECT_NE(errorOf([&] { convertRaw(bad, spec(64, 64, 8, RawType::UInt8)); }).find(bad), std::string::npos);
}

// zlib's gzread stopped quietly at bytes that are not another gzip member (issue 12).
TEST_F(Raw, TrailingGarbageAfterGzipIsRefusedConcatenatedMembersAreRead) {
    const Bytes data = pattern8(16 * 16 * 4);
    const std::string gz = writeGz("t.raw.gz", data);
    std::ifstream in(gz, std::ios::binary);
    const Bytes member((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Bytes tail = member;
    for (const char c : std::string("garbage")) tail.push_back(static_cast<unsigned char>(c));
    const std::string bad = writePlain("tail.raw.gz", tail);
    const std::string msg = errorOf([&] { convertRaw(bad, spec(16, 16, 4, RawType::UInt8)); });
    EXPECT_NE(msg.find("trailing garbage"), std::string::npos) << msg;
    EXPECT_NE(msg.find(bad), std::string::npos) << msg;
    // Two members of half the data each (what `cat a.gz b.gz` makes) read as one stream.
    const std::string first = writeGz("a.gz", Bytes(data.begin(), data.begin() + data.size() / 2));
    const std::string second = writeGz("b.gz", Bytes(data.begin() + data.size() / 2, data.end()));
    std::ifstream ia(first, std::ios::binary), ib(second, std::ios::binary);
    Bytes both((std::istreambuf_iterator<char>(ia)), std::istreambuf_iterator<char>());
    both.insert(both.end(), std::istreambuf_iterator<char>(ib), std::istreambuf_iterator<char>());
    const auto joined = convertRaw(writePlain("both.raw.gz", both), spec(16, 16, 4, RawType::UInt8));
    const auto plain = convertRaw(writePlain("p.raw", data), spec(16, 16, 4, RawType::UInt8));
    EXPECT_EQ(joined->activeVoxelCount(), plain->activeVoxelCount());
    EXPECT_EQ(joined->tree().getValue(Coord(15, 15, 3)), plain->tree().getValue(Coord(15, 15, 3)));
}

// 130 KB of gzip'd 0xFF became 1.3·10⁸ active voxels: X*Y*Z is bounded before reading.
TEST_F(Raw, VoxelCountIsBoundedBeforeReading) {
    const std::string path = writePlain("small.raw", pattern8(8));
    RawSpec big = spec(512, 512, 512, RawType::UInt8);
    const std::string msg = errorOf([&] { convertRaw(path, big); });
    EXPECT_NE(msg.find("--dims"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--max-voxels"), std::string::npos) << msg;
    big.maxVoxels = kHardMaxRawVoxels;  // raised: now the size check speaks
    EXPECT_NE(errorOf([&] { convertRaw(path, big); }).find("size mismatch"), std::string::npos);
}

TEST_F(Raw, MissingFileAndDirectory) {
    EXPECT_NE(errorOf([&] { convertRaw(dir_ + "/nope.raw", spec(1, 1, 1, RawType::UInt8)); }).find("no such file"),
              std::string::npos);
    EXPECT_NE(errorOf([&] { convertRaw(dir_, spec(1, 1, 1, RawType::UInt8)); }).find("not a regular file"),
              std::string::npos);
}

// The path every convert format shares (NRRD and VTI feed it bytes as they decode them).
TEST(DensityBuilder, VoxelsSplitAcrossCallsBigEndianInt16AndFloat64) {
    const auto unit = openvdb::math::Transform::createLinearTransform(1.0);
    DensityBuilder u16({{3, 1, 1}, RawType::UInt16, true}, 0.0, unit);
    const Bytes big{0x01, 0x00, 0xff, 0xff, 0x00, 0x02};  // 256, 65535, 2 (big-endian)
    for (unsigned char b : big) u16.addBytes(&b, 1);       // one byte at a time: voxels split across calls
    auto acc = u16.grid()->getConstAccessor();
    EXPECT_FLOAT_EQ(acc.getValue(Coord(0, 0, 0)), 256.0f / 65535.0f);
    EXPECT_FLOAT_EQ(acc.getValue(Coord(1, 0, 0)), 1.0f);
    EXPECT_FLOAT_EQ(acc.getValue(Coord(2, 0, 0)), 2.0f / 65535.0f);
    EXPECT_EQ(u16.bytes(), u16.expectedBytes());

    DensityBuilder i16({{2, 2, 1}, RawType::Int16, false}, 0.0, unit);
    const Bytes little{0xff, 0xff, 0xff, 0x7f, 0x00, 0x80, 0x01, 0x00};  // -1, 32767, -32768, 1
    i16.addBytes(little.data(), little.size());
    EXPECT_EQ(i16.stats().active, 2u);  // negatives are below the default threshold
    EXPECT_FLOAT_EQ(i16.grid()->tree().getValue(Coord(1, 0, 0)), 1.0f);
    EXPECT_FLOAT_EQ(i16.grid()->tree().getValue(Coord(1, 1, 0)), 1.0f / 32767.0f);

    DensityBuilder f64({{3, 1, 1}, RawType::Float64, false}, 0.0, unit);
    for (double v : {0.5, 1e300, 2.0}) {
        const uint64_t bits = std::bit_cast<uint64_t>(v);
        unsigned char b[8];
        for (int k = 0; k < 8; ++k) b[k] = static_cast<unsigned char>(bits >> (8 * k));
        f64.addBytes(b, 8);
    }
    EXPECT_EQ(f64.stats().nonFinite, 1u);  // beyond float32's range
    EXPECT_EQ(f64.stats().active, 2u);
    EXPECT_EQ(f64.grid()->tree().getValue(Coord(2, 0, 0)), 2.0f);
    f64.addBytes(big.data(), big.size());  // bytes past the last voxel are counted, not added
    EXPECT_EQ(f64.bytes(), f64.expectedBytes() + big.size());
    EXPECT_EQ(f64.stats().active, 2u);
}

TEST(RawParse, DimsTypeAndSpacing) {
    EXPECT_EQ(parseDims("256,256,128", "--dims"), (std::array<int, 3>{256, 256, 128}));
    for (const char* bad : {"256,256", "1,2,3,4", "0,1,1", "a,b,c", "70000,1,1", "1,,1", "1.5,2,3", ""}) {
        try {
            parseDims(bad, "--dims");
            ADD_FAILURE() << "accepted --dims " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("--dims"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(parseRawType("uint16", "--type"), RawType::UInt16);
    EXPECT_THROW(parseRawType("int8", "--type"), Error);
    EXPECT_EQ(parseRawType("int16", "--type"), RawType::Int16);
    EXPECT_EQ(parseRawType("float64", "--type"), RawType::Float64);
    EXPECT_EQ(parseSpacing("0.5,0.5,0.5", "--spacing"), (std::array<double, 3>{0.5, 0.5, 0.5}));
    // Anisotropic voxels are accepted (the renderer draws ellipsoids) and kept per axis.
    EXPECT_EQ(parseSpacing("1,1,2.5", "--spacing"), (std::array<double, 3>{1.0, 1.0, 2.5}));
    const auto xform = spacingTransform({1.0, 1.0, 2.5});
    EXPECT_NEAR(xform->voxelSize().z(), 2.5, 1e-12);
    EXPECT_NEAR(xform->indexToWorld(openvdb::Vec3d(1, 2, 3)).z(), 7.5, 1e-12);
    EXPECT_THROW(parseSpacing("1,1,0", "--spacing"), Error);
    EXPECT_THROW(parseSpacing("-1,-1,-1", "--spacing"), Error);
    EXPECT_THROW(parseSpacing("1,1", "--spacing"), Error);
    // 1e-7 gave OpenVDB's "Non-zero scale values required"; 1e300 failed later at --eye.
    for (const char* bad : {"1e-7,1e-7,1e-7", "1e300,1e300,1e300", "5e-5,5e-5,5e-5", "2e6,2e6,2e6"}) {
        const std::string msg = errorOf([&] { parseSpacing(bad, "--spacing"); });
        EXPECT_NE(msg.find("--spacing"), std::string::npos) << msg;
        EXPECT_NE(msg.find("outside"), std::string::npos) << msg;
    }
    EXPECT_EQ(parseSpacing("1e-4,1e-4,1e-4", "--spacing")[0], 1e-4);
    EXPECT_EQ(parseSpacing("1e6,1e6,1e6", "--spacing")[2], 1e6);
}

/// Converts a shared volume, or skips the test when it is absent.
openvdb::FloatGrid::Ptr sharedVolume(const std::string& name, int z, double threshold) {
    const std::string path = std::string(VDBSPLAT_SHARED_DIR) + "/volumes/" + name;
    if (!fs::exists(path)) return nullptr;
    return convertRaw(path, spec(256, 256, z, RawType::UInt8, threshold));
}

TEST(RawShared, EngineActiveCountsAndBounds) {
    auto all = sharedVolume("engine_256x256x128_uint8.raw.gz", 128, 0.0);
    if (!all) GTEST_SKIP() << "../shared/volumes/engine_256x256x128_uint8.raw.gz is absent";
    // MANIFEST.md: fraction of voxels > 0 is 0.620, > 30 is 0.158 (of 8,388,608).
    EXPECT_EQ(all->activeVoxelCount(), 5198360u);
    EXPECT_NEAR(all->activeVoxelCount() / 8388608.0, 0.620, 0.0005);
    EXPECT_EQ(all->evalActiveVoxelBoundingBox(), openvdb::CoordBBox(Coord(0, 0, 0), Coord(255, 255, 127)));
    auto dense = sharedVolume("engine_256x256x128_uint8.raw.gz", 128, 30 / 255.0);
    EXPECT_EQ(dense->activeVoxelCount(), 1322412u);
    EXPECT_NEAR(dense->activeVoxelCount() / 8388608.0, 0.158, 0.0005);
    EXPECT_EQ(dense->evalActiveVoxelBoundingBox(), openvdb::CoordBBox(Coord(61, 24, 0), Coord(203, 222, 107)));
}

TEST(RawShared, BonsaiActiveFractionsMatchTheManifest) {
    auto all = sharedVolume("bonsai_256x256x256_uint8.raw.gz", 256, 0.0);
    if (!all) GTEST_SKIP() << "../shared/volumes/bonsai_256x256x256_uint8.raw.gz is absent";
    EXPECT_NEAR(all->activeVoxelCount() / 16777216.0, 0.203, 0.0005);
    auto dense = sharedVolume("bonsai_256x256x256_uint8.raw.gz", 256, 30 / 255.0);
    EXPECT_NEAR(dense->activeVoxelCount() / 16777216.0, 0.114, 0.0005);
    const auto box = dense->evalActiveVoxelBoundingBox();
    EXPECT_TRUE(openvdb::CoordBBox(Coord(0), Coord(255)).isInside(box));
    EXPECT_GT(box.volume(), 0u);
}

}  // namespace
}  // namespace vdbsplat
