// tests/footprint/prefilter_test.cpp — PrefilterRamp (footprint/prefilter.h): the low-pass a
// primitive carries by its projected spacing, against its definition sampled densely: the two
// plateaus, a continuous linear ramp between, monotone, and the edge cases (NaN, ±∞, a flat ramp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "footprint/prefilter.h"

namespace vdbsplat {
namespace {

constexpr double kMinified = 0.1, kMagnified = 0.05;

TEST(PrefilterRamp, PlateausAndALinearRampBetween) {
    const PrefilterRamp ramp(kMinified, kMagnified);
    const double end = PrefilterRamp::kStart + 1.0 / PrefilterRamp::kInvWidth;
    for (const double s : {0.0, 1e-9, 0.25, PrefilterRamp::kStart}) EXPECT_EQ(ramp.at(s), kMinified) << s;
    for (const double s : {end, end + 1e-9, 2.0, 37.0, 1e300}) EXPECT_NEAR(ramp.at(s), kMagnified, 1e-15) << s;
    // Between: the straight line through the two ends, to rounding.
    for (int i = 1; i < 100; ++i) {
        const double s = PrefilterRamp::kStart + (end - PrefilterRamp::kStart) * i / 100.0;
        const double line = kMinified + (kMagnified - kMinified) * (s - PrefilterRamp::kStart) / (end - PrefilterRamp::kStart);
        EXPECT_NEAR(ramp.at(s), line, 1e-15) << s;
    }
}

TEST(PrefilterRamp, ContinuousAndMonotone) {
    const PrefilterRamp ramp(kMinified, kMagnified);
    double previous = ramp.at(0.0);
    for (int i = 1; i <= 40000; ++i) {  // s from 0 to 4 px in steps of 1e-4
        const double s = i * 1e-4, v = ramp.at(s);
        EXPECT_LE(v, previous) << s;                                             // never rises
        EXPECT_LE(previous - v, (kMinified - kMagnified) * 2.1e-4 + 1e-15) << s;  // no jump (slope 2·span)
        previous = v;
    }
}

TEST(PrefilterRamp, EdgeCases) {
    const PrefilterRamp ramp(kMinified, kMagnified);
    EXPECT_EQ(ramp.at(std::numeric_limits<double>::quiet_NaN()), kMinified);
    EXPECT_EQ(ramp.at(-1.0), kMinified);
    EXPECT_EQ(ramp.at(-INFINITY), kMinified);
    EXPECT_NEAR(ramp.at(INFINITY), kMagnified, 1e-15);
    // A flat ramp (the prefilter order, EWA, Swan, none) is its value everywhere, exactly.
    for (const double v : {kPrefilterVariance, 0.0}) {
        const PrefilterRamp flat(v, v);
        for (const double s : {0.0, 0.7, 1.0, 3.0, double(INFINITY)}) EXPECT_EQ(flat.at(s), v) << s;
    }
    // The default is V_h everywhere (what a context without a ramp folds in).
    EXPECT_EQ(PrefilterRamp().at(0.2), kPrefilterVariance);
    EXPECT_EQ(PrefilterRamp().at(5.0), kPrefilterVariance);
}

}  // namespace
}  // namespace vdbsplat
