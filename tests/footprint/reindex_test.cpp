// tests/footprint/reindex_test.cpp — d(i, α) (DESIGN §3) settled by brute force: the
// normalised ray–centre distance of on-axis pixel rays. Regression test: the seed's
// misprinted denominator tan α must FAIL the same comparison.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "footprint/ellipse.h"
#include "footprint/reindex.h"

namespace vdbsplat {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// Max over on-axis pixels inside the ellipse of |formula(i, α) − |c × v|/(|v| r)|.
double maxOnAxisError(const std::function<double(double, double)>& formula, double alphaDeg) {
    const double D = 5.0, r = D * std::sin(alphaDeg * kDeg), f = 250.0;
    const SphereProjection s = projectSphere({0.0, 0.0, D}, r, f, {0.0, 0.0});
    double worst = 0.0;
    for (int k = 0; k <= 400; ++k) {
        // a pixel along a diagonal, from the centre to the silhouette
        const double i = k / 400.0;
        const PixelCoord p = s.centre + i * s.a * glm::normalize(glm::dvec2(1.0, -2.0));
        EXPECT_NEAR(s.index(p), i, 1e-12);
        worst = std::max(worst, std::abs(formula(s.index(p), s.alpha()) - exactRayDistance(s, p)));
    }
    return worst;
}

TEST(Reindex, SinAlphaDenominatorMatchesBruteForceOnAxis) {
    for (double alpha : {0.01, 1.0, 5.0, 10.0, 15.0, 30.0, 45.0, 60.0, 80.0})
        EXPECT_LT(maxOnAxisError(reindex, alpha), 1e-12) << "alpha " << alpha;
}

TEST(Reindex, MisprintedTanAlphaDenominatorFailsTheBruteForce) {
    // The seed's d = sin(atan(i tanα))/tanα gives d(1) = cos α: off by 1 − cos α at the silhouette.
    for (double alpha : {5.0, 15.0, 30.0, 60.0}) {
        const double err = maxOnAxisError(reindexMisprinted, alpha);
        EXPECT_GT(err, 0.9 * (1.0 - std::cos(alpha * kDeg))) << "alpha " << alpha;
        EXPECT_GT(err, 1e-3) << "alpha " << alpha;
    }
}

TEST(Reindex, SilhouetteAndCentreAndSquaredForm) {
    for (double alpha : {0.0, 0.1, 10.0, 45.0, 89.0}) {
        const double a = alpha * kDeg;
        EXPECT_NEAR(reindex(1.0, a), 1.0, 1e-14);
        EXPECT_EQ(reindex(0.0, a), 0.0);
        for (double i = 0.0; i <= 1.0; i += 0.05) {
            EXPECT_NEAR(reindex2(i * i, a), reindex(i, a) * reindex(i, a), 1e-14);
            EXPECT_GE(reindex(i, a), i - 1e-15);  // perspective pushes d outward
        }
    }
}

TEST(Reindex, PinnedSpotValue) {
    // d(0.5, 10°) = 0.5 / √(cos²10° + 0.25 sin²10°), computed independently (Python, double).
    EXPECT_NEAR(reindex(0.5, 10.0 * kDeg), 0.5057515575199761, 1e-15);
}

}  // namespace
}  // namespace vdbsplat
