// tests/volume/test_generate.cpp — the procedural volumes of volume/generate.h:
// active counts, bounding boxes, values against the closed forms, the cloud's count
// tolerance, determinism by seed and across thread counts, and option validation.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "util/error.h"
#include "volume/generate.h"
#include "volume/grid.h"

namespace vdbsplat {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

/// Active voxels of `vdbsplat generate tubes` with the defaults (res 128, 14 tubes, 2 sheets,
/// radius 0.7–2.5, seed 1); also in volumes/make-generated.sh.
constexpr uint64_t kPinnedTubesActive = 34740;

/// True when @p a and @p b have the same active voxels with bit-identical values.
bool sameGrid(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b) {
    if (a.activeVoxelCount() != b.activeVoxelCount()) return false;
    auto acc = b.getConstAccessor();
    for (auto it = a.cbeginValueOn(); it; ++it)
        if (!acc.isValueOn(it.getCoord()) || acc.getValue(it.getCoord()) != *it) return false;
    return true;
}

TEST(Generate, CheckerBoxDefaultIsTheSeedPapersBox) {
    GenerateOptions opt{"checkerbox"};
    auto grid = generateVolume(opt);
    EXPECT_EQ(grid->getName(), "density");
    EXPECT_EQ(grid->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(grid->activeVoxelCount(), 1000000u);
    EXPECT_EQ(grid->evalActiveVoxelBoundingBox(), CoordBBox(Coord(0), Coord(99)));
    auto acc = grid->getConstAccessor();
    EXPECT_EQ(acc.getValue(Coord(0, 0, 0)), kCheckerDensityEven);
    EXPECT_EQ(acc.getValue(Coord(9, 9, 9)), kCheckerDensityEven);
    EXPECT_EQ(acc.getValue(Coord(10, 0, 0)), kCheckerDensityOdd);
    EXPECT_EQ(acc.getValue(Coord(10, 10, 0)), kCheckerDensityEven);
    EXPECT_EQ(acc.getValue(Coord(99, 99, 99)), kCheckerDensityOdd);  // cells 9+9+9 = 27
    EXPECT_FALSE(acc.isValueOn(Coord(100, 0, 0)));
}

TEST(Generate, CheckerBoxScalesItsCellsWithRes) {
    GenerateOptions opt{"checkerbox", 30};
    auto grid = generateVolume(opt);
    EXPECT_EQ(grid->activeVoxelCount(), 27000u);
    size_t dense = 0;
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        const Coord c = it.getCoord();
        const int parity = (c.x() / 3 + c.y() / 3 + c.z() / 3) % 2;
        ASSERT_EQ(*it, parity == 0 ? kCheckerDensityEven : kCheckerDensityOdd) << c;
        dense += parity == 0;
    }
    EXPECT_EQ(dense, 500u * 27u);  // 500 of the 1000 cells, 27 voxels each
}

TEST(Generate, MarschnerLobbClosedFormSpotValues) {
    EXPECT_NEAR(marschnerLobb(0, 0, 0), 0.6, 1e-12);   // (1 − 0 + α·2) / (2(1+α))
    EXPECT_NEAR(marschnerLobb(1, 0, -1), 1.0, 1e-12);  // r = 1: cos(2π f cos(π/2)) = 1; sin(−π/2) = −1
    EXPECT_NEAR(marschnerLobb(0, 0, 1), 0.2, 1e-12);   // α·2 / (2(1+α))
}

TEST(Generate, MarschnerLobbGridSamplesTheSignal) {
    auto grid = generateVolume(GenerateOptions{"marschner-lobb"});
    EXPECT_EQ(grid->activeVoxelCount(), 41u * 41u * 41u);
    EXPECT_EQ(grid->evalActiveVoxelBoundingBox(), CoordBBox(Coord(0), Coord(40)));
    auto acc = grid->getConstAccessor();
    EXPECT_NEAR(acc.getValue(Coord(20, 20, 20)), 0.6f, 1e-6);
    EXPECT_NEAR(acc.getValue(Coord(40, 20, 0)), 1.0f, 1e-6);
    float lo = 1, hi = 0;
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        const Coord c = it.getCoord();
        const double f = marschnerLobb(-1 + c.x() / 20.0, -1 + c.y() / 20.0, -1 + c.z() / 20.0);
        ASSERT_NEAR(*it, f, 1e-6) << c;
        lo = std::min(lo, *it), hi = std::max(hi, *it);
    }
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, 1.0f);
    EXPECT_LT(lo, 0.05f);  // the signal spans nearly all of [0,1]
    EXPECT_GT(hi, 0.95f);
}

TEST(Generate, SphereMatchesBruteForce) {
    const int res = 40;
    auto grid = generateVolume(GenerateOptions{"sphere", res});
    const double c = (res - 1) / 2.0;
    uint64_t expected = 0;
    auto acc = grid->getConstAccessor();
    for (int k = 0; k < res; ++k)
        for (int j = 0; j < res; ++j)
            for (int i = 0; i < res; ++i) {
                const double q = ((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)) / (c * c);
                const bool inside = q < 1.0;
                expected += inside;
                ASSERT_EQ(acc.isValueOn(Coord(i, j, k)), inside);
                if (inside) {
                    ASSERT_NEAR(acc.getValue(Coord(i, j, k)), (1 - q) * (1 - q), 1e-6);
                }
            }
    EXPECT_EQ(grid->activeVoxelCount(), expected);
    EXPECT_EQ(grid->evalActiveVoxelBoundingBox(), CoordBBox(Coord(1), Coord(res - 2)));
    EXPECT_NEAR(double(expected), M_PI / 6 * std::pow(res - 1.0, 3), 0.03 * expected);
}

TEST(Generate, CloudHitsTheRequestedCount) {
    for (uint64_t n : {1000ull, 20000ull, 300000ull}) {
        auto grid = makeCloud(n, 1);
        const double count = double(grid->activeVoxelCount());
        EXPECT_NEAR(count, double(n), kCloudCountTolerance * n) << "--active " << n;
        float lo = 1, hi = 0;
        for (auto it = grid->cbeginValueOn(); it; ++it) lo = std::min(lo, *it), hi = std::max(hi, *it);
        EXPECT_GT(lo, 0.0f);
        EXPECT_EQ(hi, 1.0f);
        // Sparse: the leaves hold not much more than the active voxels (memory ∝ active).
        EXPECT_LT(double(grid->tree().leafCount()) * 512.0, 4.0 * count + 20 * 512.0) << "--active " << n;
    }
}

TEST(Generate, CloudIsDeterministicBySeedAndThreadCount) {
    auto a = makeCloud(50000, 7);
    auto b = makeCloud(50000, 7);
    EXPECT_TRUE(sameGrid(*a, *b));
    auto c = makeCloud(50000, 8);
    EXPECT_FALSE(sameGrid(*a, *c));
    openvdb::FloatGrid::Ptr serial;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        serial = makeCloud(50000, 7);
    }
    EXPECT_TRUE(sameGrid(*a, *serial));
}

/// Issue 10's reference volume (the defaults): its active count is pinned, so a change to the
/// layout or the profile shows; the same seed gives the same grid, another seed another one.
TEST(Generate, TubesAreDeterministicBySeedAndThreadCount) {
    GenerateOptions opt{"tubes"};
    opt.validate();
    EXPECT_EQ(*opt.res, kDefaultTubesRes);
    EXPECT_EQ(*opt.count, kDefaultTubeCount);
    auto a = generateVolume(opt);
    EXPECT_EQ(a->activeVoxelCount(), kPinnedTubesActive);
    auto b = generateVolume(opt);
    EXPECT_TRUE(sameGrid(*a, *b));
    openvdb::FloatGrid::Ptr serial;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        serial = generateVolume(opt);
    }
    EXPECT_TRUE(sameGrid(*a, *serial));
    GenerateOptions other = opt;
    other.seed = 2;
    EXPECT_FALSE(sameGrid(*a, *generateVolume(other)));
}

/// Geometry: voxels on a tube's axis are active with density 1, voxels past radius + falloff
/// from every tube and sheet are inactive, and every active value is the profile of the
/// distance to the nearest primitive.
TEST(Generate, TubesFollowTheirLayout) {
    const int res = 64, count = 5, sheets = 1;
    const double rmin = 0.7, rmax = 2.5;
    const uint64_t seed = 3;
    const auto layout = tubeLayout(res, count, sheets, rmin, rmax, seed);
    ASSERT_EQ(layout.size(), size_t(count + sheets));
    auto grid = makeTubes(res, count, sheets, rmin, rmax, seed);
    auto acc = grid->getConstAccessor();
    int onAxis = 0;
    for (const TubePrimitive& t : layout) {
        if (t.sheet) continue;
        EXPECT_GE(t.r, rmin);
        EXPECT_LE(t.r, rmax);
        EXPECT_GE((t.b - t.a).length(), 0.5 * res);
        for (double u : {0.25, 0.5, 0.75}) {  // the voxel nearest a point of the axis
            const openvdb::Vec3d p = (1 - u) * (1 - u) * t.a + 2 * u * (1 - u) * t.m + u * u * t.b;
            const Coord c(int(std::lround(p.x())), int(std::lround(p.y())), int(std::lround(p.z())));
            EXPECT_TRUE(acc.isValueOn(c)) << c;
            EXPECT_GT(acc.getValue(c), 0.25f) << c;  // ≤ √3/2 voxel from the axis
            if (tubeDistance(t, openvdb::Vec3d(c.x(), c.y(), c.z())) <= t.r) {
                EXPECT_EQ(acc.getValue(c), 1.0f) << c;
                ++onAxis;
            }
        }
    }
    EXPECT_GT(onAxis, 0);
    uint64_t far = 0, checked = 0;
    for (int z = 0; z < res; z += 3)
        for (int y = 0; y < res; y += 3)
            for (int x = 0; x < res; x += 3) {
                const openvdb::Vec3d p(x, y, z);
                double v = 0.0;
                for (const TubePrimitive& t : layout) v = std::max(v, tubeProfile(tubeDistance(t, p), t.r));
                const Coord c(x, y, z);
                EXPECT_EQ(acc.isValueOn(c), v > 0.0) << c;
                EXPECT_NEAR(acc.getValue(c), v, 1e-6) << c;
                far += v == 0.0, ++checked;
            }
    EXPECT_GT(far, checked / 2);  // thin: most of the box is empty
}

TEST(Generate, TubeProfileIsSmooth) {
    EXPECT_EQ(tubeProfile(0.0, 1.0), 1.0);
    EXPECT_EQ(tubeProfile(1.0, 1.0), 1.0);
    EXPECT_NEAR(tubeProfile(1.5, 1.0), 0.5625, 1e-12);  // (1 − 0.25)²
    EXPECT_EQ(tubeProfile(2.0, 1.0), 0.0);
    EXPECT_EQ(tubeProfile(7.0, 1.0), 0.0);
}

TEST(Generate, GridsLoadAsVolumes) {
    for (const auto& kind : generatorKinds()) {
        GenerateOptions opt{kind};
        if (kind == "cloud") opt.active = 5000;
        Volume v = makeVolume(generateVolume(opt));
        EXPECT_EQ(v.voxelSize, 1.0) << kind;
        EXPECT_EQ(v.nonFiniteCount, 0u) << kind;
        EXPECT_GE(v.valueMin, 0.0f) << kind;
        EXPECT_LE(v.valueMax, 1.0f) << kind;
    }
}

TEST(Generate, RejectsBadOptions) {
    auto fails = [](GenerateOptions o, const std::string& needle) {
        try {
            o.validate();
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
            return;
        }
        ADD_FAILURE() << "accepted " << o.kind << ", expected an error about " << needle;
    };
    fails({"teapot"}, "teapot");
    fails({"cloud", 64}, "--res");
    fails({"sphere", std::nullopt, 100}, "--active");
    fails({"checkerbox", std::nullopt, std::nullopt, 3}, "--seed");
    fails({"sphere", std::nullopt, std::nullopt, std::nullopt, 4}, "--count");
    fails({"cloud", std::nullopt, std::nullopt, std::nullopt, std::nullopt, 1}, "--sheets");
    fails({"checkerbox", std::nullopt, std::nullopt, std::nullopt, std::nullopt, std::nullopt, 1.0}, "--radius");
    fails({"tubes", std::nullopt, std::nullopt, std::nullopt, -1}, "--count");
    fails({"tubes", std::nullopt, std::nullopt, std::nullopt, std::nullopt, -2}, "--sheets");
    fails({"tubes", std::nullopt, std::nullopt, std::nullopt, std::nullopt, std::nullopt, 3.0, 2.0}, "--radius-min");
    fails({"tubes", std::nullopt, std::nullopt, std::nullopt, std::nullopt, std::nullopt, 0.01}, "--radius");
    fails({"tubes", std::nullopt, 100}, "--active");
    fails({"checkerbox", 4096}, "--res");  // 6.9e10 voxels
    fails({"checkerbox", 5000}, "--res");
    fails({"sphere", 2}, "--res");
    fails({"cloud", std::nullopt, 0}, "--active");
    fails({"cloud", std::nullopt, kMaxGeneratedVoxels + 1}, "--active");
    GenerateOptions ok{"cloud"};
    ok.validate();
    EXPECT_EQ(*ok.active, kDefaultCloudActive);
    EXPECT_EQ(*ok.seed, kDefaultCloudSeed);
}

}  // namespace
}  // namespace vdbsplat
