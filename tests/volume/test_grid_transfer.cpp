// tests/volume/test_grid_transfer.cpp — the child→parent grid hand-over of loadVolume
// (volume/grid_transfer.h): loadVolume equals a plain OpenVDB read (converted and sanitized
// as before) on generated float and double grids with leaves, active and inactive tiles at
// every level, NaN/inf values and several transforms; the transfer round-trips in memory;
// and a damaged transfer (truncated, counts too large, bad levels, misaligned or
// overlapping leaves, flipped bytes) is refused with an Error, never a crash.
#include <gtest/gtest.h>

#include <openvdb/io/File.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>

#include "support/error_of.h"
#include "util/error.h"
#include "volume/generate.h"
#include "volume/grid.h"
#include "volume/grid_transfer.h"
#include "grid_compare.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using openvdb::Coord;
using test::errorOf;
using namespace test;

class GridTransfer : public ::testing::Test {
protected:
    void SetUp() override {
        initOpenVdb();
        char tmpl[] = "/tmp/vdbsplat_transfer_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string write(const std::string& name, openvdb::GridPtrVec grids) const {
        const std::string p = dir_ + "/" + name;
        openvdb::io::File(p).write(grids);
        return p;
    }
    std::string dir_;
};

TEST_F(GridTransfer, LoadEqualsPlainReadForFloatAndDoubleGrids) {
    auto f = mixedGrid<openvdb::FloatGrid>("float");
    f->setTransform(rotated());
    auto d = mixedGrid<openvdb::DoubleGrid>("double");
    d->setTransform(openvdb::math::Transform::createLinearTransform(0.125));
    auto moved = mixedGrid<openvdb::FloatGrid>("moved");
    moved->transform().postTranslate(openvdb::Vec3d(5, 6, -7));
    auto half = mixedGrid<openvdb::FloatGrid>("half");
    half->setSaveFloatAsHalf(true);
    const std::string file = write("mixed.vdb", {f, d, moved, half});
    for (const char* name : {"float", "double", "moved", "half"}) {
        SCOPED_TRACE(name);
        const Volume want = plainRead(file, name);
        const Volume got = loadVolume(file, name);
        EXPECT_EQ(got.nonFiniteCount, 128u * 128 * 128 + 3);  // the NaN level-2 tile and three voxels
        EXPECT_EQ(got.valueMin, -3.5f);
        EXPECT_EQ(got.valueMax, 2.5f);
        EXPECT_EQ(got.file, file);
        expectSameVolume(want, got);
    }
}

TEST_F(GridTransfer, LoadEqualsPlainReadForGeneratedVolumes) {
    for (const char* kind : {"sphere", "checkerbox"}) {
        GenerateOptions o;
        o.kind = kind;
        o.res = 40;
        const std::string file = dir_ + "/" + kind + ".vdb";
        writeVolume(file, generateVolume(o));
        SCOPED_TRACE(kind);
        expectSameVolume(plainRead(file, "density"), loadVolume(file));
    }
    const std::string cloud = write("cloud.vdb", {makeCloud(200000, 5)});
    const Volume got = loadVolume(cloud);
    expectSameVolume(plainRead(cloud, got.name), got);
}

TEST(GridTransferMemory, RoundTripKeepsTreeTransformNameAndLog) {
    initOpenVdb();
    auto d = mixedGrid<openvdb::DoubleGrid>("dbl");
    d->setTransform(rotated());
    const std::vector<char> bytes = encodeGridTransfer(*d, "WARNING: a line\n");
    std::vector<std::pair<uint64_t, uint64_t>> released;
    const DecodedGrid got = decodeGridTransfer(bytes.data(), bytes.size(), "x.vdb",
                                               [&](uint64_t a, uint64_t b) { released.emplace_back(a, b); });
    EXPECT_EQ(got.log, "WARNING: a line\n");
    EXPECT_EQ(got.grid->getName(), "dbl");
    EXPECT_EQ(got.grid->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(got.grid->transform(), d->transform());
    ASSERT_FALSE(released.empty());
    EXPECT_EQ(released.back().second, bytes.size());
    auto want = openvdb::FloatGrid::create(std::make_shared<openvdb::FloatTree>(d->tree()));
    Volume sanitized = makeVolume(want, "x.vdb");
    expectSameTree(*sanitized.tree, got.grid->tree());
    EXPECT_EQ(got.activeVoxels, sanitized.activeVoxels);
    EXPECT_EQ(got.nonFiniteCount, sanitized.nonFiniteCount);
    EXPECT_EQ(got.valueMin, sanitized.valueMin);
    EXPECT_EQ(got.valueMax, sanitized.valueMax);
    // Other value types are refused by name.
    auto ints = openvdb::Int32Grid::create(0);
    ints->setName("labels");
    EXPECT_NE(errorOf([&] { encodeGridTransfer(*ints); }).find("int32"), std::string::npos);
}

// Layout offsets the damage below aims at (grid_transfer.cpp): header fields, then records.
struct Damage {
    const char* what;
    size_t offset;
    uint64_t value;
    int bytes;
};

TEST(GridTransferMemory, DamagedTransfersAreRefusedWithAnError) {
    initOpenVdb();
    auto g = mixedGrid<openvdb::FloatGrid>("density");
    const std::vector<char> good = encodeGridTransfer(*g, "");
    ASSERT_NO_THROW(decodeGridTransfer(good.data(), good.size(), "x.vdb"));
    const auto refused = [&](const std::vector<char>& bytes, const std::string& why) {
        const std::string e = errorOf([&] { decodeGridTransfer(bytes.data(), bytes.size(), "x.vdb"); });
        EXPECT_EQ(e.rfind("x.vdb: damaged grid transfer (", 0), 0u) << why << ": " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << why;
    };
    // Truncated at every length of the header and strings, then coarser.
    for (size_t n = 0; n < good.size(); n += (n < 512 ? 1 : 977)) refused(std::vector<char>(good.begin(), good.begin() + n), "cut " + std::to_string(n));
    std::vector<char> longer = good;
    longer.resize(good.size() + 2128);
    refused(longer, "longer");
    // Header fields: total size, leaf and tile counts (too large, huge), string lengths, class, magic.
    const Damage fields[] = {{"magic", 0, 0, 1},
                             {"total", 8, good.size() + 2128, 8},
                             {"leaves+1", 16, 0, -1},
                             {"leaves huge", 16, uint64_t(1) << 62, 8},
                             {"leaves max", 16, ~uint64_t(0), 8},
                             {"tiles+1", 24, 0, -1},
                             {"tiles huge", 24, uint64_t(1) << 61, 8},
                             {"name length", 32, 0xffffffffu, 4},
                             {"transform length", 36, 5000, 4},
                             {"transform length small", 36, 3, 4},
                             {"log length", 40, 0x7fffffffu, 4},
                             {"grid class", 44, 99, 4}};
    for (const Damage& d : fields) {
        std::vector<char> bad = good;
        if (d.bytes < 0) {  // count + 1
            uint64_t v;
            std::memcpy(&v, bad.data() + d.offset, 8);
            ++v;
            std::memcpy(bad.data() + d.offset, &v, 8);
        } else {
            std::memcpy(bad.data() + d.offset, &d.value, size_t(d.bytes));
        }
        refused(bad, d.what);
    }
    // Records: a tile level of 0 and 7, a misaligned tile, a misaligned leaf, a repeated leaf.
    uint64_t leaves, tiles;
    std::memcpy(&leaves, good.data() + 16, 8);
    std::memcpy(&tiles, good.data() + 24, 8);
    ASSERT_GE(tiles, 4u);
    ASSERT_GE(leaves, 2u);
    const size_t leavesAt = good.size() - leaves * 2128, tilesAt = leavesAt - tiles * 24;
    for (uint32_t level : {0u, 4u, 7u}) {
        std::vector<char> bad = good;
        std::memcpy(bad.data() + tilesAt + 12, &level, 4);
        refused(bad, "tile level " + std::to_string(level));
    }
    {
        std::vector<char> bad = good;
        const int32_t x = 3;
        std::memcpy(bad.data() + tilesAt, &x, 4);
        refused(bad, "misaligned tile");
        bad = good;
        std::memcpy(bad.data() + leavesAt + 2128 + 4, &x, 4);
        refused(bad, "misaligned leaf");
        bad = good;
        std::memcpy(bad.data() + leavesAt + 2128, bad.data() + leavesAt, 16);
        refused(bad, "repeated leaf");
        bad = good;
        const uint32_t active = 2;
        std::memcpy(bad.data() + tilesAt + 20, &active, 4);
        refused(bad, "tile state");
    }
    // Random bytes anywhere: an Error or a grid, nothing else (values may change: they are data).
    std::mt19937 rng(20261123);
    for (int trial = 0; trial < 300; ++trial) {
        std::vector<char> bad = good;
        const size_t span = trial % 2 ? bad.size() : std::min<size_t>(bad.size(), tilesAt + tiles * 24 + 64);
        for (int k = 0, n = 1 + int(rng() % 8); k < n; ++k) bad[rng() % span] = char(rng());
        try {
            decodeGridTransfer(bad.data(), bad.size(), "x.vdb");
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()).rfind("x.vdb: damaged grid transfer (", 0), 0u) << e.what();
        }
    }
}

}  // namespace
}  // namespace vdbsplat
