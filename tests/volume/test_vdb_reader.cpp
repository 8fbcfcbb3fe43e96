// tests/volume/test_vdb_reader.cpp — vdbsplat's own .vdb reader (volume/vdb_reader.h):
// it reads what OpenVDB writes — every compression (none, zlib, blosc, with and without
// active-mask compression), half-float storage, float and double grids, all seven per-node
// inactive-value modes, tiles at every level, the linear maps, every generator's volumes —
// into the same tree, transform and metadata as OpenVDB's own read, bit for bit; it leaves
// what it does not cover to OpenVDB (returns nothing), and loadVolume still reads those;
// and every damaged grid (cut short at every byte of every section, lying chunk sizes,
// blosc and zlib chunks that lie about their contents, masks that disagree with the data,
// any byte overwritten) ends in one Error naming the file, never a crash.
#include <gtest/gtest.h>

#include <openvdb/io/Compression.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include "grid_compare.h"
#include "support/error_of.h"
#include "util/error.h"
#include "volume/generate.h"
#include "volume/grid.h"
#include "volume/vdb_reader.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using namespace test;
using openvdb::Coord;

class VdbReader : public ::testing::Test {
protected:
    void SetUp() override {
        initOpenVdb();
        char tmpl[] = "/tmp/vdbsplat_reader_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return dir_ + "/" + name; }
    std::string write(const std::string& name, openvdb::GridPtrVec grids, uint32_t compression) const {
        openvdb::io::File file(path(name));
        file.setCompression(compression);
        file.write(grids);
        return path(name);
    }
    std::string dir_;
};

bool has(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

std::string slurp(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Leaves whose inactive values take each of the seven forms the writer compresses
/// differently (io::NO_MASK_OR_INACTIVE_VALS … NO_MASK_AND_ALL_VALS, in that order along x:
/// checked by parsing a file written with COMPRESS_ZIP | COMPRESS_ACTIVE_MASK), background 2:
/// all 2; all -2; all 5; 2 and -2; 2 and 7; 6 and 7; 1, 3 and 4.
openvdb::FloatGrid::Ptr inactiveValueModes(const std::string& name) {
    auto g = openvdb::FloatGrid::create(2.0f);
    g->setName(name);
    auto& tree = g->tree();
    const std::vector<std::vector<float>> inactive = {{2}, {-2}, {5}, {2, -2}, {2, 7}, {6, 7}, {1, 3, 4}};
    for (int mode = 0; mode < 7; ++mode) {
        const Coord origin(16 * mode, 0, 0);
        const std::vector<float>& values = inactive[size_t(mode)];
        for (int i = 0; i < 512; ++i)
            tree.setValueOff(origin.offsetBy(i >> 6, (i >> 3) & 7, i & 7), values[size_t(i) % values.size()]);
        for (int i = 0; i < 8; ++i) tree.setValueOn(origin.offsetBy(i, i, i), 0.1f * float(i + mode));
    }
    return g;
}

/// Every flavour of grid the reader covers, one grid each (names: float, double, half, …).
openvdb::GridPtrVec coveredGrids() {
    auto f = mixedGrid<openvdb::FloatGrid>("float");
    f->setTransform(rotated());
    auto d = mixedGrid<openvdb::DoubleGrid>("double");
    d->setTransform(openvdb::math::Transform::createLinearTransform(0.125));
    auto half = mixedGrid<openvdb::FloatGrid>("half");
    half->setSaveFloatAsHalf(true);
    half->transform().postTranslate(openvdb::Vec3d(5, 6, -7));  // a UniformScaleTranslateMap
    auto halfDouble = mixedGrid<openvdb::DoubleGrid>("half-double");
    halfDouble->setSaveFloatAsHalf(true);
    auto scaled = mixedGrid<openvdb::FloatGrid>("scaled");
    scaled->setTransform(std::make_shared<openvdb::math::Transform>(
        std::make_shared<openvdb::math::ScaleMap>(openvdb::Vec3d(0.5, 1, 2))));
    auto shifted = mixedGrid<openvdb::FloatGrid>("shifted");
    shifted->setTransform(std::make_shared<openvdb::math::Transform>(
        std::make_shared<openvdb::math::TranslationMap>(openvdb::Vec3d(1, 2, 3))));
    auto scaleShift = mixedGrid<openvdb::FloatGrid>("scale-shift");
    scaleShift->setTransform(std::make_shared<openvdb::math::Transform>(
        std::make_shared<openvdb::math::ScaleTranslateMap>(openvdb::Vec3d(0.5, 1, 2), openvdb::Vec3d(1, 2, 3))));
    auto modes = inactiveValueModes("modes");
    modes->insertMeta("frames", openvdb::Int64Metadata(7));
    modes->insertMeta("note", openvdb::StringMetadata("user metadata"));
    modes->insertMeta("axis", openvdb::Vec3DMetadata(openvdb::Vec3d(1, 2, 3)));
    auto halfModes = inactiveValueModes("half-modes");
    halfModes->setSaveFloatAsHalf(true);
    openvdb::GridPtrVec all{f, d, half, halfDouble, scaled, shifted, scaleShift, modes, halfModes};
    // OpenVDB never zips fog volumes and level sets (Archive::setGridCompression): most grids
    // here are of class unknown, so that COMPRESS_ZIP reaches their nodes; one of each other.
    for (auto& grid : all) grid->setGridClass(openvdb::GRID_UNKNOWN);
    scaleShift->setGridClass(openvdb::GRID_FOG_VOLUME);
    halfModes->setGridClass(openvdb::GRID_LEVEL_SET);
    return all;
}

/// readVdbGrid reads @p name of @p file itself, into what OpenVDB reads (after loadVolume's
/// conversion and sanitizing), metadata included; loadVolume agrees.
/// @p asked: the name given to readVdbGrid ("": its default choice, which must be @p name).
void expectReadAsOpenVdb(const std::string& file, const std::string& name, const std::string& asked) {
    SCOPED_TRACE(file + " grid " + name + " asked as '" + asked + "'");
    std::string why;
    const std::optional<ReadGrid> got = readVdbGrid(file, asked, &why);
    ASSERT_TRUE(got) << "left to OpenVDB: " << why;
    const Volume want = plainRead(file, name);
    const openvdb::FloatGrid::Ptr grid = toOpenVdbGrid(*got);  // what OpenVDB makes of the same bytes
    Volume read = makeVolume(grid, file);  // already sanitized: the statistics are the reader's
    read.nonFiniteCount = got->nonFiniteCount;
    read.valueMin = got->valueMin;
    read.valueMax = got->valueMax;
    expectSameVolume(want, read);
    EXPECT_EQ(got->activeVoxels, want.activeVoxels);
    openvdb::io::File plain(file);
    plain.open(false);
    const openvdb::GridBase::Ptr base = plain.readGrid(name);
    expectSameMetadata(*base, *grid);  // "is_saved_as_half_float" included, as OpenVDB reads it
    EXPECT_EQ(base->transform(), grid->transform());
    EXPECT_EQ(base->transform().mapType(), grid->transform().mapType());
    // The name and the map readVdbGrid parsed itself (no libopenvdb) are OpenVDB's.
    EXPECT_EQ(got->name, base->getName());
    EXPECT_EQ(got->map->type(), base->transform().mapType());
    EXPECT_TRUE(got->map->isEqual(*base->transform().baseMap()));
    expectSameVolume(want, loadVolume(file, asked));
}

void expectReadAsOpenVdb(const std::string& file, const std::string& name) { expectReadAsOpenVdb(file, name, name); }

TEST_F(VdbReader, ReadsEveryCompressionAndGridFlavourAsOpenVdbDoes) {
    namespace io = openvdb::io;
    for (const uint32_t compression :
         {uint32_t(io::COMPRESS_NONE), uint32_t(io::COMPRESS_ZIP), uint32_t(io::COMPRESS_BLOSC),
          uint32_t(io::COMPRESS_ACTIVE_MASK), uint32_t(io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK),
          uint32_t(io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK)}) {
        const std::string file = write("c" + std::to_string(compression) + ".vdb", coveredGrids(), compression);
        for (const auto& grid : coveredGrids()) expectReadAsOpenVdb(file, grid->getName());
    }
}

TEST_F(VdbReader, ReadsEveryGeneratedVolumeAsOpenVdbDoes) {
    for (const std::string& kind : generatorKinds()) {
        GenerateOptions o;
        o.kind = kind;
        if (kind == "cloud")
            o.active = 30000;
        else
            o.res = 24;
        const std::string file = path(kind + ".vdb");
        writeVolume(file, generateVolume(o));
        expectReadAsOpenVdb(file, "density");
        expectReadAsOpenVdb(file, "density", "");  // the default choice
    }
}

// The value range is measured leaf by leaf in parallel lanes; of two equal extremes it keeps
// the one a serial pass over the tree meets first, as before: only +0 and -0 can tell.
TEST_F(VdbReader, RangeKeepsTheFirstOfEqualExtremesLikeASerialPass) {
    for (const bool dense : {false, true}) {
        for (const float first : {0.0f, -0.0f}) {
            auto g = openvdb::FloatGrid::create(0.0f);
            g->setName("density");
            if (dense) g->tree().fill(openvdb::CoordBBox(Coord(0), Coord(7)), 1.0f, true);  // a full leaf
            g->tree().setValueOn(Coord(0, 0, 2), first);       // lane 2 of the first word
            g->tree().setValueOn(Coord(0, 0, 5), -first);      // lane 1: a naive lane merge picks this one
            g->tree().setValueOn(Coord(64, 0, 0), -first);     // a later leaf
            g->tree().setValueOn(Coord(0, 8, 0), std::numeric_limits<float>::quiet_NaN());  // not in the range
            const std::string file = write("zeros.vdb", {g}, openvdb::io::COMPRESS_BLOSC);
            const auto got = readVdbGrid(file, "");
            ASSERT_TRUE(got);
            const Volume want = plainRead(file, "density");
            EXPECT_TRUE(sameBits(got->valueMin, want.valueMin)) << dense << " " << first;
            EXPECT_TRUE(sameBits(got->valueMin, first)) << dense << " " << first;
            EXPECT_TRUE(sameBits(got->valueMax, want.valueMax)) << dense << " " << first;
            EXPECT_EQ(got->nonFiniteCount, 1u);
        }
    }
}

// The test data above does reach all seven per-node modes: the leaf buffers of
// inactiveValueModes, written with zlib and active-mask compression, walked here by hand.
TEST_F(VdbReader, TestDataCoversEveryNodeCompressionMode) {
    auto g = inactiveValueModes("modes");
    g->setGridClass(openvdb::GRID_UNKNOWN);
    const std::string bytes = slurp(write("modes.vdb", {g}, openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK));
    int64_t gridPos = 0, blockPos = 0, endPos = 0;
    size_t at = 8 + 4 + 8 + 1 + 36 + 4 + 4;  // header, no file metadata, grid count
    for (int str = 0; str < 3; ++str) {
        uint32_t n = 0;
        std::memcpy(&n, bytes.data() + at, 4);
        at += 4 + n;
    }
    std::memcpy(&gridPos, bytes.data() + at, 8);
    std::memcpy(&blockPos, bytes.data() + at + 8, 8);
    std::memcpy(&endPos, bytes.data() + at + 16, 8);
    std::vector<int> modes;
    for (size_t p = size_t(blockPos); p < size_t(endPos);) {
        const int mode = bytes[p + 64];
        modes.push_back(mode);
        p += 64 + 1 + (mode == 2 || mode == 4 || mode == 5 ? 4 : 0) + (mode == 5 ? 4 : 0) +
             (mode >= 3 && mode <= 5 ? 64 : 0);
        int64_t n = 0;
        std::memcpy(&n, bytes.data() + p, 8);
        p += 8 + size_t(n > 0 ? n : -n);
    }
    EXPECT_EQ(modes, (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
    expectReadAsOpenVdb(path("modes.vdb"), "modes");
}

TEST_F(VdbReader, ChoosesTheGridLoadVolumeChose) {
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->tree().setValueOn(Coord(1, 2, 3), openvdb::Vec3s(1, 2, 3));
    auto flame = mixedGrid<openvdb::FloatGrid>("flame");
    auto density = mixedGrid<openvdb::DoubleGrid>("density");
    density->tree().setValueOn(Coord(40, 40, 40), 9.0);
    const std::string file = write("several.vdb", {vel, flame, density}, openvdb::io::COMPRESS_BLOSC);
    const auto got = readVdbGrid(file, "");
    ASSERT_TRUE(got);
    EXPECT_EQ(got->name, "density");  // by name, wherever it stands
    EXPECT_EQ(readVdbGrid(file, "flame")->name, "flame");
    const std::string noDensity = write("flame.vdb", {vel, flame}, openvdb::io::COMPRESS_BLOSC);
    EXPECT_EQ(readVdbGrid(noDensity, "")->name, "flame");  // else the first scalar grid
}

// What the reader leaves to OpenVDB: nothing returned, the reason given, and loadVolume reads
// the file as before (or words the error as before).
TEST_F(VdbReader, LeavesWhatItDoesNotCoverToOpenVdb) {
    auto grid = mixedGrid<openvdb::FloatGrid>("density");
    std::string why;
    {  // no grid offsets: written by io::Stream
        const std::string file = path("stream.vdb");
        std::ofstream out(file, std::ios::binary);
        openvdb::io::Stream(out).write(openvdb::GridCPtrVec{grid});
        out.close();
        EXPECT_FALSE(readVdbGrid(file, "density", &why));
        EXPECT_EQ(why, "a file without grid offsets (io::Stream)");
        expectSameVolume(plainRead(file, "density"), loadVolume(file, "density"));
    }
    {  // an instance: two grids sharing one tree (its descriptor has no data offset: 0)
        auto twin = grid->copyGrid();
        twin->setName("twin");
        const std::string file = write("instance.vdb", {grid, twin}, openvdb::io::COMPRESS_BLOSC);
        EXPECT_FALSE(readVdbGrid(file, "twin", &why));
        EXPECT_EQ(why, "an instanced grid");
        // checkVdbStructure refuses such files before either reader sees them (as before).
        EXPECT_TRUE(has(errorOf([&] { loadVolume(file, "twin"); }), "grid extends past the end of the file"));
    }
    {  // two grids of one name (OpenVDB suffixes them)
        auto again = mixedGrid<openvdb::FloatGrid>("density");
        const std::string file = write("twice.vdb", {grid, again}, openvdb::io::COMPRESS_BLOSC);
        EXPECT_FALSE(readVdbGrid(file, "density", &why));
        EXPECT_EQ(loadVolume(file, "density").activeVoxels, grid->activeVoxelCount());
    }
    {  // a frustum map
        auto frustum = mixedGrid<openvdb::FloatGrid>("density");
        frustum->setTransform(openvdb::math::Transform::createFrustumTransform(
            openvdb::BBoxd(openvdb::Vec3d(0), openvdb::Vec3d(10)), 0.5, 2.0, 1.0));
        const std::string file = write("frustum.vdb", {frustum}, openvdb::io::COMPRESS_BLOSC);
        EXPECT_FALSE(readVdbGrid(file, "density", &why));
        EXPECT_EQ(why, "a map type not read here");
        EXPECT_TRUE(errorOf([&] { loadVolume(file); }).find("transform is not linear") != std::string::npos);
    }
    {  // no such grid, not a scalar grid: OpenVDB's path words the error, as before
        auto vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->tree().setValueOn(Coord(1, 2, 3), openvdb::Vec3s(1, 2, 3));
        const std::string file = write("vel.vdb", {vel}, openvdb::io::COMPRESS_BLOSC);
        EXPECT_FALSE(readVdbGrid(file, "vel", &why));
        EXPECT_FALSE(readVdbGrid(file, "nope", &why));
        EXPECT_EQ(errorOf([&] { loadVolume(file, "nope"); }), file + ": no grid named 'nope'");
        EXPECT_EQ(errorOf([&] { loadVolume(file, "vel"); }),
                  file + ": grid 'vel' holds vec3s values; only float and double grids can be rendered");
    }
}

// ---- damaged grids -------------------------------------------------------------------------

/// Offsets in a file written by io::File with default file metadata: where the first grid's
/// descriptor keeps gridPos, and the three offsets themselves.
struct Layout {
    size_t offsetsAt = 0;
    int64_t gridPos = 0, blockPos = 0, endPos = 0;
};

Layout layoutOf(const std::string& bytes) {
    size_t at = 8 + 4 + 8 + 1 + 36;
    const auto u32 = [&](size_t p) {
        uint32_t v;
        std::memcpy(&v, bytes.data() + p, 4);
        return v;
    };
    EXPECT_EQ(u32(at), 0u);  // no file metadata
    at += 4 + 4;             // metadata count, grid count
    for (int s = 0; s < 3; ++s) at += 4 + u32(at);  // name, type, instance parent
    Layout l;
    l.offsetsAt = at;
    std::memcpy(&l.gridPos, bytes.data() + at, 8);
    std::memcpy(&l.blockPos, bytes.data() + at + 8, 8);
    std::memcpy(&l.endPos, bytes.data() + at + 16, 8);
    return l;
}

template <typename T>
void poke(std::string& bytes, size_t at, T value) {
    std::memcpy(bytes.data() + at, &value, sizeof(T));
}

/// readVdbGrid on @p bytes must throw one Error naming the label (no other exception, no crash).
std::string damagedError(const std::string& bytes) {
    try {
        const auto read = readVdbGrid(bytes.data(), bytes.size(), "bad.vdb", "");
        ADD_FAILURE() << (read ? "read a damaged grid" : "left a damaged grid to OpenVDB");
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind("bad.vdb: ", 0), 0u) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        return what;
    }
    return "";
}

/// A few leaves (one voxel inactive, not the background), active tiles at levels 1, 2 and 3,
/// user metadata: every section of a grid, small enough to damage at every byte.
openvdb::FloatGrid::Ptr smallMixed() {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    g->insertMeta("note", openvdb::StringMetadata("user metadata"));
    auto& tree = g->tree();
    for (int i = 0; i < 40; ++i) tree.setValueOn(Coord(i, 2 * i % 7, i % 9), 0.05f * float(i));
    tree.setValueOff(Coord(5, 5, 5), 3.0f);
    tree.addTile(1, Coord(64, 0, 0), 0.5f, true);
    tree.addTile(2, Coord(256, 0, 0), 0.75f, true);
    tree.addTile(3, Coord(8192, 0, 0), 1.5f, true);
    return g;
}

/// Byte positions of a grid to damage: every one near the ends of its header and topology and
/// the start of its buffers, every @p step-th elsewhere (the node masks in between).
std::vector<int64_t> positions(const Layout& l, int64_t step) {
    std::vector<int64_t> at;
    for (int64_t p = l.gridPos; p < l.endPos;) {
        at.push_back(p);
        const bool near = p < l.gridPos + 600 || (p > l.blockPos - 1500 && p < l.blockPos + 600);
        p += near ? 1 : step;
    }
    return at;
}

// The grid's sections end where its descriptor says: cut there at every byte (the file's
// bytes stay, so only the reader's bounds can stop it), each read ends in an Error.
TEST_F(VdbReader, GridCutShortAtEveryByteIsAnError) {
    namespace io = openvdb::io;
    for (const uint32_t compression : {uint32_t(io::COMPRESS_NONE), uint32_t(io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK),
                                       uint32_t(io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK)}) {
        const std::string good = slurp(write("cut.vdb", {smallMixed()}, compression));
        const Layout l = layoutOf(good);
        ASSERT_TRUE(readVdbGrid(good.data(), good.size(), "good.vdb", ""));
        int errors = 0;
        for (const int64_t cut : positions(l, 7)) {
            std::string bad = good;
            poke(bad, l.offsetsAt + 8, std::min(l.blockPos, cut));
            poke(bad, l.offsetsAt + 16, cut);
            SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(l.endPos));
            const std::string what = damagedError(bad);
            errors += has(what, "truncated or corrupt VDB file");
            if (::testing::Test::HasFailure()) return;
        }
        EXPECT_GT(errors, 2000);
    }
}

/// A dense grid of side³ voxels (no inactive values in any leaf): its first leaf buffer starts at blockPos.
std::string denseFile(const std::string& name, uint32_t compression, int side) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    std::mt19937 rng(3);
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j)
            for (int k = 0; k < side; ++k) g->tree().setValueOn(Coord(i, j, k), float(rng() % 1000) / 999.f);
    openvdb::io::File file(name);
    file.setCompression(compression);
    file.write({g});
    return slurp(name);
}

TEST_F(VdbReader, ChunksThatLieAreErrors) {
    namespace io = openvdb::io;
    // A leaf buffer: value mask (64 bytes), mode byte, then the chunk: int64 size and data.
    const std::string blosc = denseFile(path("blosc.vdb"), io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK, 16);
    const Layout l = layoutOf(blosc);
    const size_t chunk = size_t(l.blockPos) + 64 + 1;
    int64_t size = 0;
    std::memcpy(&size, blosc.data() + chunk, 8);
    ASSERT_GT(size, 16);
    ASSERT_LT(size, 2048);
    std::string bad = blosc;
    poke(bad, chunk, int64_t(1) << 62);  // past the grid's end
    EXPECT_TRUE(has(damagedError(bad), "blosc chunk at byte"));
    bad = blosc;
    poke(bad, chunk, size - 1);  // shorter than its blosc header says
    EXPECT_TRUE(has(damagedError(bad), "invalid blosc chunk"));
    bad = blosc;
    poke(bad, chunk, size + 1);  // longer
    EXPECT_TRUE(has(damagedError(bad), "blosc chunk"));
    bad = blosc;
    poke(bad, chunk + 8 + 4, uint32_t(4096));  // blosc header: holds 4096 bytes, not 2048
    EXPECT_TRUE(has(damagedError(bad), "blosc chunk"));
    bad = blosc;
    poke(bad, chunk, int64_t(-100));  // raw, of the wrong size
    EXPECT_TRUE(has(damagedError(bad), "raw chunk size"));
    bad = blosc;
    for (int64_t i = 16; i < size; ++i) bad[chunk + 8 + size_t(i)] = char(0xA5);  // the compressed stream itself
    const std::string garbled = damagedError(bad);
    EXPECT_TRUE(has(garbled, "blosc chunk")) << garbled;

    // One leaf: its chunk ends the grid, so a size that lies shows in the chunk itself.
    const std::string zip = denseFile(path("zip.vdb"), io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK, 8);
    const Layout z = layoutOf(zip);
    const size_t zchunk = size_t(z.blockPos) + 64 + 1;
    std::memcpy(&size, zip.data() + zchunk, 8);
    ASSERT_GT(size, 16);
    bad = zip;
    poke(bad, zchunk, size + 100);  // past the grid's end
    EXPECT_TRUE(has(damagedError(bad), "zlib chunk at byte"));
    bad = zip;
    poke(bad, zchunk, size - 1);  // one byte short of its stream
    const std::string tooShort = damagedError(bad);
    EXPECT_TRUE(has(tooShort, "zlib chunk of " + std::to_string(size - 1) + " bytes that does not inflate to exactly 2048"))
        << tooShort;
    bad = zip;
    for (int64_t i = 2; i < size; i += 3) bad[zchunk + 8 + size_t(i)] ^= char(0x5A);
    EXPECT_TRUE(has(damagedError(bad), "zlib chunk"));
    bad = zip;
    poke(bad, zchunk, int64_t(-(1ll << 62)));
    EXPECT_TRUE(has(damagedError(bad), "raw chunk size"));
}

// Counts that lie: the grid's metadata count, the root node's tile and child counts.
TEST_F(VdbReader, CountsThatLieAreErrors) {
    const std::string good = slurp(write("counts.vdb", {smallMixed()}, openvdb::io::COMPRESS_BLOSC));
    const Layout l = layoutOf(good);
    // After the map (UniformScaleMap: five Vec3d): buffer count, background, tile and child counts.
    const size_t map = good.find(std::string("\x0f\0\0\0UniformScaleMap", 19));
    ASSERT_NE(map, std::string::npos);
    const size_t tiles = map + 19 + 120 + 4 + 4, children = tiles + 4;
    uint32_t tileCount = 0, childCount = 0;
    std::memcpy(&tileCount, good.data() + tiles, 4);
    std::memcpy(&childCount, good.data() + children, 4);
    ASSERT_EQ(tileCount, 1u);   // the level-3 tile
    ASSERT_EQ(childCount, 1u);  // the upper node at the origin holds the leaves and the lower tiles
    for (const uint32_t lie : {0xFFFFFFFFu, 0x10000u}) {
        std::string bad = good;
        poke(bad, tiles, lie);
        EXPECT_TRUE(has(damagedError(bad), "root node tile or child count")) << lie;
        bad = good;
        poke(bad, children, lie);
        EXPECT_TRUE(has(damagedError(bad), "root node tile or child count")) << lie;
    }
    std::string bad = good;
    poke(bad, children, childCount + 1);  // one more upper node than the topology holds
    EXPECT_TRUE(has(damagedError(bad), "truncated or corrupt VDB file"));
    bad = good;
    poke(bad, size_t(l.gridPos) + 4, int32_t(0x7FFFFFFF));  // the grid's metadata count
    EXPECT_TRUE(has(damagedError(bad), "metadata count"));
}

TEST_F(VdbReader, MasksThatDisagreeWithTheDataAreErrors) {
    namespace io = openvdb::io;
    // The last leaf's topology mask is the 64 bytes before blockPos; with active-mask
    // compression its chunk holds exactly its active values: one more bit lies.
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    for (int i = 0; i < 8; ++i) g->tree().setValueOn(Coord(i, 0, 0), 1.0f + float(i));
    for (const uint32_t compression : {uint32_t(io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK),
                                       uint32_t(io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK),
                                       uint32_t(io::COMPRESS_ACTIVE_MASK)}) {
        const std::string good = slurp(write("mask.vdb", {g}, compression));
        const Layout l = layoutOf(good);
        std::string bad = good;
        bad[size_t(l.blockPos) - 1] = char(0xFF);  // voxels 504..511 of the leaf: on
        const std::string what = damagedError(bad);
        EXPECT_TRUE(has(what, "truncated or corrupt VDB file")) << what;
        // Child and value masks that overlap are OpenVDB's to read (and refuse or not), as before.
    }
}

// Any byte of the grid overwritten: a grid, nothing (OpenVDB's turn), or one Error; never a
// crash or another exception (under the sanitizers: no report).
TEST_F(VdbReader, EveryOverwrittenByteEndsCleanly) {
    const std::string good =
        slurp(write("flip.vdb", {smallMixed()}, openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK));
    int read = 0, left = 0, errors = 0;
    std::vector<int64_t> at = positions(layoutOf(good), 5);
    for (int64_t p = 0; p < layoutOf(good).gridPos; ++p) at.push_back(p);  // the file's header and descriptor
    for (const int64_t p : at) {
        for (const char byte : {char(0xFF), char(0x00), char(0x80)}) {
            std::string bad = good;
            if (bad[size_t(p)] == byte) continue;
            bad[size_t(p)] = byte;
            try {
                if (readVdbGrid(bad.data(), bad.size(), "bad.vdb", ""))
                    ++read;
                else
                    ++left;
            } catch (const Error& e) {
                ++errors;
                EXPECT_EQ(std::string(e.what()).rfind("bad.vdb: ", 0), 0u) << e.what();
            }
        }
    }
    EXPECT_GT(errors, 100);
    EXPECT_GT(read, 100);  // values and inactive masks: still a grid
    EXPECT_GT(left, 0);    // e.g. a node compression mode byte out of range
}

// More leaves than one batch (4096): read as OpenVDB reads them through the mapped file
// (prefaulted ahead, released behind), and cut short in any batch, an Error.
TEST_F(VdbReader, ManyLeavesAreReadBatchByBatch) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    for (int i = 0; i < 9000; ++i) g->tree().setValueOn(Coord(8 * (i % 100), 8 * (i / 100), i % 8), 0.001f * float(i));
    ASSERT_EQ(g->tree().leafCount(), 9000u);
    const std::string file = write("many.vdb", {g}, openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    expectReadAsOpenVdb(file, "density");
    const std::string good = slurp(file);
    const Layout l = layoutOf(good);
    for (const double at : {0.2, 0.5, 0.9}) {
        std::string bad = good;
        poke(bad, l.offsetsAt + 16, l.blockPos + int64_t(at * double(l.endPos - l.blockPos)));
        EXPECT_TRUE(has(damagedError(bad), "truncated or corrupt VDB file")) << at;
    }
}

TEST_F(VdbReader, FilesThatCannotBeMappedAreErrors) {
    EXPECT_TRUE(has(errorOf([&] { readVdbGrid(path("missing.vdb"), ""); }), "missing.vdb: cannot open for reading"));
    EXPECT_TRUE(has(errorOf([&] { readVdbGrid(dir_, ""); }), ": not a regular file"));
}

}  // namespace
}  // namespace vdbsplat
