// tests/pointfilter/point_filter_test.cpp — the point's circular pixel filter (DESIGN §4)
// and THE energy test of issue 3: at the threshold (h·f/z = 1 px) the splat's summed
// deposit equals the point's summed deposit for the same voxel within 1%.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/prefilter.h"
#include "footprint/screen_kernel.h"
#include "footprint/tables.h"
#include "pointfilter/point_filter.h"
#include "render/project_modes.h"
#include "support/targets.h"

namespace vdbsplat {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double weightSum(const PointFootprint& fp) {
    double s = 0.0;
    for (int k = 0; k < fp.nx * fp.ny; ++k) s += fp.w[k];
    return s;
}

TEST(PointFilter, VarianceIsPrefilterPlusProjectedFootprint) {
    EXPECT_DOUBLE_EQ(pointFilterVariance(0.0), kPrefilterVariance);
    EXPECT_NEAR(pointFilterVariance(1.0), kPrefilterVariance + 0.65 * 0.65, 1e-15);
    EXPECT_NEAR(pointFilterVariance(0.5), kPrefilterVariance + 0.325 * 0.325, 1e-15);
}

TEST(PointFilter, WeightMatchesTheGaussian) {
    EXPECT_LT(point_filter_weight::maxAbsError(), 5e-7);  // the series' remainder, 1.7e−7, and float roundings (1.6e−7 measured)
    EXPECT_FLOAT_EQ(pointFilterWeight(0.0f), 1.0f);
    EXPECT_EQ(pointFilterWeight(9.0f), 0.0f);
    EXPECT_EQ(pointFilterWeight(std::nanf("")), 0.0f);
}

TEST(PointFilter, WeightsSumToOneWithinSevenBySeven) {
    for (double spacing : {0.0, 0.3, 0.7, 1.0, 1.5, 3.0})
        for (double fx = 0.0; fx < 1.0; fx += 0.125)
            for (double fy = 0.0; fy < 1.0; fy += 0.25) {
                const PointFootprint fp = rasterizePoint({100.0 + fx, 37.0 + fy}, pointFilterVariance(spacing));
                EXPECT_LE(fp.nx, kPointMaxSide);
                EXPECT_LE(fp.ny, kPointMaxSide);
                EXPECT_GE(fp.nx, 5);  // V = 1: centres strictly within 3 px
                EXPECT_NEAR(weightSum(fp), 1.0, 1e-6);
                for (int k = 0; k < fp.nx * fp.ny; ++k) EXPECT_GE(fp.w[k], 0.0f);
            }
}

TEST(PointFilter, ShapeIsTheTruncatedGaussianAndSymmetric) {
    const double V = pointFilterVariance(1.0);
    const PointFootprint fp = rasterizePoint({10.5, 20.5}, V);  // at a pixel centre
    ASSERT_EQ(fp.nx, 7);
    ASSERT_EQ(fp.ny, 7);
    EXPECT_EQ(fp.x0, 7);
    EXPECT_EQ(fp.y0, 17);
    const float c = fp.at(3, 3);
    for (int iy = 0; iy < 7; ++iy)
        for (int ix = 0; ix < 7; ++ix) {
            EXPECT_FLOAT_EQ(fp.at(ix, iy), fp.at(6 - ix, iy));
            EXPECT_FLOAT_EQ(fp.at(ix, iy), fp.at(iy, ix));
            const double r2 = (ix - 3) * (ix - 3) + (iy - 3) * (iy - 3);
            const double rs = std::min(3.0 * std::sqrt(V), kPointMaxRadiusPx);
            const double expected = r2 < rs * rs ? std::exp(-r2 / (2.0 * V)) : 0.0;
            EXPECT_NEAR(fp.at(ix, iy) / c, expected, 1e-5);
        }
}

TEST(PointFilter, DepositTotalIsSigmaMTimesProjectedArea) {
    const double sigma = 3.0, h = 0.02, f = 500.0;
    // On-axis: σ·M·(f/z)² = σ·h·(h f/z)².
    EXPECT_NEAR(pointDepositTotal(sigma, h, f, {0.0, 0.0, 10.0}), sigma * h * 1.0, 1e-15);
    // Off-axis by θ: the exact screen total grows by D/z = 1/cos θ.
    const ViewPoint c{10.0 * std::tan(30.0 * kDeg), 0.0, 10.0};
    EXPECT_NEAR(pointDepositTotal(sigma, h, f, c), sigma * h / std::cos(30.0 * kDeg), 1e-12);
    EXPECT_EQ(pointDepositTotal(sigma, h, f, {0.0, 0.0, -1.0}), 0.0);
}

struct EnergyCase {
    double thetaDeg, phiDeg, subX, subY;
};

/// Summed splat deposit (table path and exact path) and point deposit of one voxel.
struct Energy {
    double splatTable = 0.0, splatExact = 0.0, point = 0.0, maxPixelDiff = 0.0, peak = 0.0;
};

Energy energyAt(const Tables& tables, const EnergyCase& ec, double spacingPx) {
    const double f = 500.0, sigma = 2.0, z = 10.0, h = spacingPx * z / f;
    const PixelCoord pp(200.0 + ec.subX, 200.0 + ec.subY);
    const double t = std::tan(ec.thetaDeg * kDeg);
    const ViewPoint c{z * t * std::cos(ec.phiDeg * kDeg), z * t * std::sin(ec.phiDeg * kDeg), z};
    const SphereProjection e = projectSphere(c, Kernel::kRadius * h, f, pp);
    const ScreenKernel k = makeScreenKernel(e);
    const SplatShader shader = makeSplatShader(k, tables, sigma, h);
    Energy out;
    // Point: projected at the projection of c (what the renderer does), weights × total.
    const PixelCoord proj(pp.x + f * c.x / c.z, pp.y - f * c.y / c.z);
    const double total = pointDepositTotal(sigma, h, f, c);
    const PointFootprint fp = rasterizePoint(proj, pointFilterVariance(spacingPx));
    for (int k2 = 0; k2 < fp.nx * fp.ny; ++k2) out.point += total * fp.w[k2];
    const PixelRange r = pixelRange(k.bounds);
    for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) {
            const PixelCoord p(x + 0.5, y + 0.5);
            const double s = splatDeposit(k, shader, p);
            out.splatTable += s;
            out.splatExact += splatDepositExact(k, e, sigma, h, p);
            double pt = 0.0;
            const int ix = x - fp.x0, iy = y - fp.y0;
            if (ix >= 0 && iy >= 0 && ix < fp.nx && iy < fp.ny) pt = total * fp.at(ix, iy);
            out.maxPixelDiff = std::max(out.maxPixelDiff, std::abs(s - pt));
            out.peak = std::max(out.peak, s);
        }
    return out;
}

TEST(PointFilterEnergy, SplatEqualsPointAtTheThresholdWithinOnePercent) {
    const Tables tables = buildTables();
    const EnergyCase cases[] = {{0.0, 0.0, 0.0, 0.0},   {0.0, 0.0, 0.37, 0.81}, {0.0, 0.0, 0.5, 0.5},
                                {10.0, 30.0, 0.2, 0.6}, {20.0, 120.0, 0.9, 0.1}, {35.0, 250.0, 0.45, 0.3}};
    std::printf("energy at the threshold (h f/z = 1 px): splat/point (table, exact), max pixel diff / peak\n");
    double worst = 0.0;
    for (const EnergyCase& ec : cases) {
        const Energy e = energyAt(tables, ec, 1.0);
        const double ratio = e.splatTable / e.point, ratioExact = e.splatExact / e.point;
        std::printf("  theta %4.1f° phi %5.1f° sub (%.2f, %.2f): %.5f  %.5f  %.4f\n", ec.thetaDeg, ec.phiDeg, ec.subX,
                    ec.subY, ratio, ratioExact, e.maxPixelDiff / e.peak);
        worst = std::max({worst, std::abs(ratio - 1.0), std::abs(ratioExact - 1.0)});
        EXPECT_NEAR(ratio, 1.0, 0.01) << "theta " << ec.thetaDeg;
        EXPECT_NEAR(ratioExact, 1.0, 0.01) << "theta " << ec.thetaDeg;
        EXPECT_LT(e.maxPixelDiff / e.peak, 0.1) << "the two kernels converge at the threshold";
    }
    RecordProperty("energy_worst_relative_deviation", testing::PrintToString(worst));
}

TEST(PointFilterEnergy, EnergyMatchesAcrossScales) {
    // Away from the threshold the two paths still carry the same total (zoom does not pop).
    const Tables tables = buildTables();
    for (double spacing : {0.5, 0.8, 1.25, 2.0}) {
        const Energy e = energyAt(tables, {15.0, 60.0, 0.3, 0.7}, spacing);
        EXPECT_NEAR(e.splatTable / e.point, 1.0, 0.01) << "spacing " << spacing;
    }
}

TEST(PointFilter, NonFiniteInputGivesNoPixels) {
    EXPECT_EQ(rasterizePoint({std::nan(""), 1.0}, 1.5).nx, 0);
    EXPECT_EQ(rasterizePoint({1e300, 1.0}, 1.5).nx, 0);
}

// The filter set up once at projection (PointSetup) gives rasterizePoint's footprint and weights
// bit for bit, pixel by pixel: float centres (what the renderer stores) anywhere in a pixel and
// on pixel centres and edges, variances from --mode none's 1/36 to the 3.5 px cap, and ones so
// small that no pixel centre lies within r_s (rasterizePoint's one-pixel fallback).
TEST(PointFilter, SetupMatchesTheFootprint) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    int checked = 0, fallbacks = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const int edge = trial % 8;  // some centres exactly on pixel centres or pixel edges
        const float fx = edge == 0 ? 0.5f : edge == 1 ? 0.f : u(rng), fy = edge == 2 ? 0.5f : edge == 3 ? 0.f : u(rng);
        const float cx = float(-20 + int(1100 * u(rng))) + fx, cy = float(-20 + int(700 * u(rng))) + fy;
        const float v = trial % 5 == 0 ? float(1e-4 + 1e-3 * u(rng))                    // tiny: the fallback
                        : trial % 5 == 1 ? float(kNearestPixelVariance)
                                         : float(pointFilterVariance(3.0 * u(rng), trial % 2 ? 0.1 : 1.0));
        const PointFootprint fp = rasterizePoint(PixelCoord(cx, cy), v);
        const PointSetup s = setupPoint(PixelCoord(cx, cy), v);
        ASSERT_EQ(s.x0, fp.x0);
        ASSERT_EQ(s.y0, fp.y0);
        ASSERT_EQ(s.nx, fp.nx);
        ASSERT_EQ(s.ny, fp.ny);
        fallbacks += s.norm == 1.0f && s.invVariance == 0.0f;
        for (int iy = 0; iy < fp.ny; ++iy)
            for (int ix = 0; ix < fp.nx; ++ix, ++checked)
                ASSERT_EQ(pointWeight(s, cx, cy, fp.x0 + ix, fp.y0 + iy), fp.at(ix, iy))
                    << "centre " << cx << ", " << cy << " V " << v << " pixel " << ix << ", " << iy;
    }
    EXPECT_GT(checked, 100000);
    EXPECT_GT(fallbacks, 100);
    EXPECT_TRUE(setupPoint({std::nan(""), 1.0}, 1.5).empty());
    EXPECT_TRUE(setupPoint({1e300, 1.0}, 1.5).empty());
    EXPECT_TRUE(setupPoint({1.0, 1.0}, 0.0).empty());
}

// The vector setup (setupPointVector: both axes' weights in one vector, the terms row by row in
// vectors, the sum in the scalar order) is the scalar setup bit for bit, for float centres (what
// the renderer stores), including centres at and near 0, past the image's edges, and the fallback.
void vectorSetupEqualsTheScalarSetup() {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    int fallbacks = 0;
    for (int trial = 0; trial < 50000; ++trial) {
        const int kind = trial % 10;
        float cx = float(-30 + int(2000 * u(rng))) + u(rng), cy = float(-30 + int(1200 * u(rng))) + u(rng);
        if (kind == 0) cx = 1e-6f * u(rng), cy = -1e-7f * u(rng);  // at and near the origin
        if (kind == 1) cx = std::floor(cx) + 0.5f;                  // on a pixel centre
        const float v = kind == 2 ? float(1e-4 + 1e-3 * u(rng))
                        : kind == 3 ? float(kNearestPixelVariance)
                                    : float(pointFilterVariance(4.0 * u(rng), trial % 2 ? 0.1 : 1.0));
        const PointSetup a = setupPoint(PixelCoord(cx, cy), v), b = setupPointVector(PixelCoord(cx, cy), v);
        ASSERT_EQ(a.x0, b.x0) << trial;
        ASSERT_EQ(a.y0, b.y0) << trial;
        ASSERT_EQ(a.nx, b.nx) << trial;
        ASSERT_EQ(a.ny, b.ny) << trial;
        ASSERT_EQ(a.invVariance, b.invVariance) << trial;
        ASSERT_EQ(a.radius2, b.radius2) << trial;
        ASSERT_EQ(a.norm, b.norm) << "trial " << trial << " centre " << cx << ", " << cy << " V " << v;
        fallbacks += a.invVariance == 0.0f && !a.empty();
    }
    EXPECT_GT(fallbacks, 100);
    EXPECT_TRUE(setupPointVector({std::nan(""), 1.0}, 1.5).empty());
}

// On every SIMD target the binary holds (the weight's float steps must agree on each).
TEST(PointFilter, VectorSetupEqualsTheScalarSetup) { test::forEachTarget([] { vectorSetupEqualsTheScalarSetup(); }); }

}  // namespace
}  // namespace vdbsplat
