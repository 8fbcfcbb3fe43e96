// tests/composite/test_point_raster.cpp — the point loop over one tile (composite/point_raster.h):
// the Highway loop against the scalar loop, bit for bit, and the scalar loop against the point's
// footprint from rasterizePoint (the filter DESIGN §4 defines), with pixels already finished.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "composite/point_raster.h"
#include "pointfilter/point_filter.h"
#include "support/targets.h"

namespace vdbsplat {
namespace {

struct SlabArrays {
    alignas(64) std::array<float, kTilePixels> tau, er, eg, eb, T;
    SlabTile tile(int x0, int y0) { return {tau.data(), er.data(), eg.data(), eb.data(), T.data(), x0, y0}; }
};

/// Random slab sums and transmittance over one tile, some pixels finished (T < @p epsilon).
void randomTile(std::mt19937& rng, SlabArrays& a, float epsilon) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (size_t i = 0; i < size_t(kTilePixels); ++i) {
        a.tau[i] = u(rng) < 0.3f ? 0.f : u(rng), a.er[i] = u(rng), a.eg[i] = u(rng), a.eb[i] = u(rng);
        a.T[i] = u(rng) < 0.2f ? epsilon * u(rng) : u(rng);
    }
}

/// The point at (@p cx, @p cy) of filter variance @p v set up as the compositor does (PointSetup)
/// and clipped to the tile at (@p tx0, @p ty0), with a random total and colour; false when its
/// filter is empty.
bool pointInTile(std::mt19937& rng, float cx, float cy, float v, int tx0, int ty0, float epsilon, PointRaster& p) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const PointSetup s = setupPoint(PixelCoord(cx, cy), v);
    if (s.empty()) return false;
    p = PointRaster{};
    p.cx = cx, p.cy = cy, p.invVariance = s.invVariance, p.radius2 = s.radius2, p.norm = s.norm;
    p.total = 0.01f + 5.f * u(rng);
    p.color = glm::vec3(u(rng), u(rng), u(rng));
    p.x0 = std::max(s.x0, tx0), p.x1 = std::min(s.x0 + s.nx - 1, tx0 + kTileSize - 1);
    p.y0 = std::max(s.y0, ty0), p.y1 = std::min(s.y0 + s.ny - 1, ty0 + kTileSize - 1);
    p.epsilon = epsilon;
    return true;
}

void vectorLoopEqualsTheScalarLoop() {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    constexpr float kEpsilon = 1e-4f;
    int drawn = 0, skippedFinished = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const int tx0 = kTileSize * int(4 * u(rng)), ty0 = kTileSize * int(4 * u(rng));  // the tile's first pixel
        SlabArrays a, b;
        randomTile(rng, a, kEpsilon);
        b = a;
        // A centre in or near the tile; variances of both low-passes and of --mode none.
        const float cx = float(tx0) - 4.f + float(kTileSize + 8) * u(rng), cy = float(ty0) - 4.f + float(kTileSize + 8) * u(rng);
        const float v = trial % 7 == 0 ? 1.f / 36.f : float(pointFilterVariance(2.5 * u(rng), trial % 2 ? 0.1 : 1.0));
        PointRaster p;
        if (!pointInTile(rng, cx, cy, v, tx0, ty0, kEpsilon, p)) continue;
        const SlabArrays before = a;
        drawPointScalar(p, a.tile(tx0, ty0));
        drawPointVector(p, b.tile(tx0, ty0));
        for (size_t i = 0; i < size_t(kTilePixels); ++i) {
            ASSERT_EQ(a.tau[i], b.tau[i]) << "trial " << trial << " pixel " << i;
            ASSERT_EQ(a.er[i], b.er[i]) << trial;
            ASSERT_EQ(a.eg[i], b.eg[i]) << trial;
            ASSERT_EQ(a.eb[i], b.eb[i]) << trial;
        }
        // --compositing slabs: three slabs taking fractions of each τ, vector against scalar.
        {
            SlabArrays sa[3], sb[3];
            SlabTargets ta, tb;
            ta.count = tb.count = 3;
            for (int j = 0; j < 3; ++j) {
                sa[j] = before, sb[j] = before;
                ta.tau[size_t(j)] = sa[j].tau.data(), ta.er[size_t(j)] = sa[j].er.data();
                ta.eg[size_t(j)] = sa[j].eg.data(), ta.eb[size_t(j)] = sa[j].eb.data();
                tb.tau[size_t(j)] = sb[j].tau.data(), tb.er[size_t(j)] = sb[j].er.data();
                tb.eg[size_t(j)] = sb[j].eg.data(), tb.eb[size_t(j)] = sb[j].eb.data();
                ta.fraction[size_t(j)] = tb.fraction[size_t(j)] = 0.2f + 0.3f * float(j);
            }
            drawPointSlabsScalar(p, ta, before.T.data(), tx0, ty0);
            drawPointSlabsVector(p, tb, before.T.data(), tx0, ty0);
            for (int j = 0; j < 3; ++j)
                for (size_t i = 0; i < size_t(kTilePixels); ++i) {
                    ASSERT_EQ(sa[j].tau[i], sb[j].tau[i]) << "trial " << trial << " slab " << j << " pixel " << i;
                    ASSERT_EQ(sa[j].eb[i], sb[j].eb[i]) << trial;
                }
        }
        // The scalar loop deposits total · w with rasterizePoint's w, on live pixels only.
        const PointFootprint fp = rasterizePoint(PixelCoord(cx, cy), v);
        for (int y = ty0; y < ty0 + kTileSize; ++y)
            for (int x = tx0; x < tx0 + kTileSize; ++x) {
                const size_t i = size_t(y - ty0) * kTileSize + size_t(x - tx0);
                const bool inside = x >= fp.x0 && x < fp.x0 + fp.nx && y >= fp.y0 && y < fp.y0 + fp.ny;
                const bool live = before.T[i] >= kEpsilon;
                const float tau = inside && live ? p.total * fp.at(x - fp.x0, y - fp.y0) : 0.f;
                ASSERT_EQ(a.tau[i], before.tau[i] + tau) << trial;
                ASSERT_EQ(a.er[i], before.er[i] + tau * p.color.x) << trial;
                drawn += tau > 0.f, skippedFinished += inside && !live;
            }
    }
    EXPECT_GT(drawn, 20000);
    EXPECT_GT(skippedFinished, 1000);
}

// On every SIMD target the CPU has: 16-lane targets draw two rows a vector, the others one.
TEST(PointRaster, VectorLoopEqualsTheScalarLoop) { test::forEachTarget([] { vectorLoopEqualsTheScalarLoop(); }); }

// One channel (a SlabTile without green and blue sums, ColorChannels::Grey): the vector and the
// scalar loops write τ and the red sums exactly as with all three, and nothing else.
void oneChannelIsTheRedOfThree() {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    int drawn = 0;
    for (int trial = 0; trial < 1000; ++trial) {
        const int tx0 = kTileSize * int(4 * u(rng)), ty0 = kTileSize * int(4 * u(rng));
        SlabArrays a;
        randomTile(rng, a, 1e-4f);
        const float cx = float(tx0) + float(kTileSize) * u(rng), cy = float(ty0) + float(kTileSize) * u(rng);
        PointRaster p;
        if (!pointInTile(rng, cx, cy, float(pointFilterVariance(2.5 * u(rng), 0.1)), tx0, ty0, 1e-4f, p)) continue;
        const SlabArrays before = a;
        SlabArrays b = a, c = a, d = a;
        drawPointVector(p, a.tile(tx0, ty0));
        drawPointVector(p, {b.tau.data(), b.er.data(), nullptr, nullptr, b.T.data(), tx0, ty0});
        drawPointScalar(p, c.tile(tx0, ty0));
        drawPointScalar(p, {d.tau.data(), d.er.data(), nullptr, nullptr, d.T.data(), tx0, ty0});
        ASSERT_EQ(a.tau, b.tau) << trial;
        ASSERT_EQ(a.er, b.er) << trial;
        ASSERT_EQ(c.tau, d.tau) << trial;
        ASSERT_EQ(c.er, d.er) << trial;
        ASSERT_EQ(b.eg, before.eg) << trial;
        ASSERT_EQ(d.eb, before.eb) << trial;
        drawn += a.tau != before.tau;
        // The slab order: two slabs, with and without green and blue sums, vector and scalar.
        for (const bool vector : {true, false}) {
            SlabArrays sa[2] = {before, before}, sb[2] = {before, before};
            SlabTargets ta, tb;
            ta.count = tb.count = 2;
            for (size_t j = 0; j < 2; ++j) {
                ta.tau[j] = sa[j].tau.data(), ta.er[j] = sa[j].er.data(), ta.eg[j] = sa[j].eg.data(), ta.eb[j] = sa[j].eb.data();
                tb.tau[j] = sb[j].tau.data(), tb.er[j] = sb[j].er.data();
                ta.fraction[j] = tb.fraction[j] = 0.3f + 0.4f * float(j);
            }
            (vector ? drawPointSlabsVector : drawPointSlabsScalar)(p, ta, before.T.data(), tx0, ty0);
            (vector ? drawPointSlabsVector : drawPointSlabsScalar)(p, tb, before.T.data(), tx0, ty0);
            for (size_t j = 0; j < 2; ++j) {
                ASSERT_EQ(sa[j].tau, sb[j].tau) << trial;
                ASSERT_EQ(sa[j].er, sb[j].er) << trial;
                ASSERT_EQ(sb[j].eg, before.eg) << trial;
            }
        }
    }
    EXPECT_GT(drawn, 500);
}
TEST(PointRaster, OneChannelIsTheRedOfThree) { test::forEachTarget([] { oneChannelIsTheRedOfThree(); }); }

}  // namespace
}  // namespace vdbsplat
