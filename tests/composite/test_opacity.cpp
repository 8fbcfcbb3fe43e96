// tests/composite/test_opacity.cpp — α = 1 − exp(−τ) of the compositor against long double.
#include <gtest/gtest.h>

#include <cmath>

#include "composite/opacity.h"

namespace vdbsplat {
namespace {

TEST(Opacity, MatchesOneMinusExpToAFewUlpsOverEveryScale) {
    double worst = 0.0;
    for (float tau = 1e-9f; tau < 60.f; tau *= 1.0013f) {
        const long double exact = -std::expm1(-static_cast<long double>(tau));
        const double rel = std::abs(static_cast<long double>(opacityFromOpticalDepth(tau)) - exact) / exact;
        worst = std::max(worst, rel);
    }
    EXPECT_LT(worst, 4e-6);  // ≤ 33 ulp of cancellation at τ = 1/32, a few ulp elsewhere
}

TEST(Opacity, EdgesAreExact) {
    EXPECT_EQ(opacityFromOpticalDepth(0.f), 0.f);
    EXPECT_EQ(opacityFromOpticalDepth(-1.f), 0.f);
    EXPECT_EQ(opacityFromOpticalDepth(NAN), 0.f);
    EXPECT_EQ(opacityFromOpticalDepth(INFINITY), 1.f);
    EXPECT_EQ(opacityFromOpticalDepth(200.f), 1.f);
    // Monotone across the switch between the series and expf.
    const float below = std::nextafter(1.f / 32.f, 0.f), at = 1.f / 32.f;
    EXPECT_LE(opacityFromOpticalDepth(below), opacityFromOpticalDepth(at));
}

}  // namespace
}  // namespace vdbsplat
