// tests/footprint/ellipse_test.cpp — the exact projected ellipse (DESIGN §2) against the
// brute-force ray–sphere oracle over a sweep of θ, α and azimuths, and the degenerate
// classes (eye inside, straddling the eye plane, behind): classified right, never NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <cstdio>
#include <numbers>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/reindex.h"

namespace vdbsplat {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ViewPoint direction(double thetaDeg, double phiDeg) {
    const double t = thetaDeg * kDeg, p = phiDeg * kDeg;
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

bool allFinite(const SphereProjection& s) {
    const double v[] = {s.D, s.alpha(), s.theta(), s.u.x, s.u.y, s.centre.x, s.centre.y, s.a, s.b,
                        s.toUnit[0][0], s.toUnit[0][1], s.toUnit[1][0], s.toUnit[1][1]};
    for (double x : v)
        if (!std::isfinite(x)) return false;
    return !std::isnan(s.bounds.lo.x) && !std::isnan(s.bounds.lo.y) && !std::isnan(s.bounds.hi.x) &&
           !std::isnan(s.bounds.hi.y);
}

/// True when the brute-force classification changes within one pixel of @p p.
bool nearBoundary(const SphereProjection& s, const PixelCoord& p) {
    const bool here = rayHitsSphere(s, p);
    for (int k = 0; k < 64; ++k) {
        const double a = 2.0 * std::numbers::pi * k / 64;
        if (rayHitsSphere(s, p + glm::dvec2(std::cos(a), std::sin(a))) != here) return true;
    }
    return false;
}

struct Coverage {
    long inside = 0, mismatches = 0, farMismatches = 0, hitsOutsideBounds = 0;
};

/// Compares the ellipse's pixel set with the pixels whose rays hit the sphere, over the
/// bounding box grown by 3 pixels.
Coverage compareCoverage(const SphereProjection& s) {
    Coverage c;
    const PixelBox grown{s.bounds.lo - 3.0, s.bounds.hi + 3.0};
    const PixelRange range = pixelRange(grown);  // no image clamp beyond 0
    for (int y = range.y0; y <= range.y1; ++y)
        for (int x = range.x0; x <= range.x1; ++x) {
            const PixelCoord p(x + 0.5, y + 0.5);
            const bool inEllipse = s.index2(p) <= 1.0, hit = rayHitsSphere(s, p);
            c.inside += inEllipse;
            const bool inBounds = p.x >= s.bounds.lo.x && p.x <= s.bounds.hi.x && p.y >= s.bounds.lo.y &&
                                  p.y <= s.bounds.hi.y;
            c.hitsOutsideBounds += hit && !inBounds;
            if (inEllipse != hit) {
                ++c.mismatches;
                c.farMismatches += !nearBoundary(s, p);
            }
        }
    return c;
}

TEST(Ellipse, MatchesBruteForceRayHitsOverThetaAlphaSweep) {
    const double thetas[] = {0.0, 2.0, 10.0, 20.0, 35.0};
    const double alphas[] = {0.05, 0.5, 2.0, 5.0, 15.0, 30.0, 45.0, 60.0};
    const double phis[] = {0.0, 37.0, 135.0, 250.0};
    const double sizes[] = {1.5, 25.0};  // semi-axis b in pixels
    int ellipses = 0, straddles = 0;
    for (double theta : thetas)
        for (double alpha : alphas)
            for (double phi : phis)
                for (double size : sizes) {
                    const double D = 10.0, r = D * std::sin(alpha * kDeg);
                    const ViewPoint c = D * direction(theta, phi);
                    const double q = c.z * c.z - r * r;
                    const double f = q > 0.0 ? size * std::sqrt(q) / r : 100.0;
                    const SphereProjection s = projectSphere(c, r, f, {320.0, 240.0});
                    SCOPED_TRACE(testing::Message() << "theta " << theta << " alpha " << alpha << " phi " << phi
                                                    << " size " << size);
                    ASSERT_TRUE(allFinite(s));
                    const bool expectEllipse = std::pow(std::cos(theta * kDeg), 2) > std::pow(std::sin(alpha * kDeg), 2);
                    if (!expectEllipse) {
                        EXPECT_EQ(s.kind, SphereClass::Straddles);
                        ++straddles;
                        continue;
                    }
                    ASSERT_EQ(s.kind, SphereClass::Ellipse);
                    ++ellipses;
                    const Coverage cov = compareCoverage(s);
                    EXPECT_EQ(cov.farMismatches, 0) << cov.mismatches << " mismatches";
                    EXPECT_EQ(cov.hitsOutsideBounds, 0);
                    EXPECT_LE(cov.mismatches, 2 + cov.inside / 1000);  // the sets are equal up to rounding
                    const double area = std::numbers::pi * s.a * s.b;
                    EXPECT_NEAR(cov.inside, area, 4.0 * (s.a + s.b) + 4.0);
                    EXPECT_GE(s.a, s.b * (1.0 - 1e-12));  // a is the major axis
                }
    EXPECT_GT(ellipses, 200);
    EXPECT_GT(straddles, 5);
    RecordProperty("ellipse_cases", ellipses);
    RecordProperty("straddle_cases", straddles);
}

TEST(Ellipse, OnAxisIsACircleAtThePrincipalPoint) {
    const SphereProjection s = projectSphere({0.0, 0.0, 10.0}, 1.0, 400.0, {200.0, 150.0});
    ASSERT_EQ(s.kind, SphereClass::Ellipse);
    EXPECT_DOUBLE_EQ(s.centre.x, 200.0);
    EXPECT_DOUBLE_EQ(s.centre.y, 150.0);
    EXPECT_NEAR(s.a, 400.0 * std::tan(std::asin(0.1)), 1e-9);
    EXPECT_NEAR(s.b, s.a, 1e-9);
    EXPECT_DOUBLE_EQ(s.theta(), 0.0);
    EXPECT_NEAR(s.alpha(), std::asin(0.1), 1e-15);
}

// The projection takes no trigonometry (α and θ are computed on demand): its closed forms
// agree with the angles' definitions, asin(r/D), acos(c.z/D) and tanθ·tanα.
TEST(Ellipse, AnglesAndAffineIndexErrorWithoutTrigonometry) {
    int ellipses = 0;
    for (double thetaDeg = 0.0; thetaDeg < 80.0; thetaDeg += 3.7)
        for (double phiDeg = 0.0; phiDeg < 360.0; phiDeg += 41.0)
            for (const double D : {1.5, 4.0, 30.0, 900.0}) {
                const ViewPoint c = D * direction(thetaDeg, phiDeg);
                const SphereProjection s = projectSphere(c, 1.0, 500.0, {200.0, 200.0});
                EXPECT_NEAR(s.alpha(), std::asin(1.0 / s.D), 1e-14);
                EXPECT_NEAR(s.theta(), std::acos(c.z / s.D), 1e-7);  // acos loses half the digits near 0
                if (!s.isEllipse()) continue;
                ++ellipses;
                const double trig = std::tan(std::acos(c.z / s.D)) * std::tan(std::asin(1.0 / s.D));
                EXPECT_NEAR(s.affineIndexError(), trig, 1e-12 * (1.0 + trig)) << thetaDeg << " " << D;
            }
    EXPECT_GT(ellipses, 100);
}

TEST(Ellipse, CentreIsNotTheProjectionOfTheCentreAndYFlips) {
    // c above the axis (y up) projects above the principal point (pixel y smaller).
    const ViewPoint c{0.0, 3.0, 8.0};
    const double f = 300.0;
    const SphereProjection s = projectSphere(c, 2.0, f, {100.0, 100.0});
    ASSERT_EQ(s.kind, SphereClass::Ellipse);
    EXPECT_NEAR(s.u.x, 0.0, 1e-15);
    EXPECT_NEAR(s.u.y, -1.0, 1e-15);
    const double projected = 100.0 - f * c.y / c.z;
    EXPECT_LT(s.centre.y, projected - 1.0);  // pushed outward, away from the axis
    // The centre is the midpoint of the silhouette's extremes A', B' along u (Appendix A).
    const double tA = std::tan(s.theta() + s.alpha()), tB = std::tan(s.theta() - s.alpha());
    EXPECT_NEAR(s.centre.y, 100.0 - f * 0.5 * (tA + tB), 1e-9);
    EXPECT_NEAR(s.a, 0.5 * f * (tA - tB), 1e-9);
}

TEST(Ellipse, EyeInsideIsExplicitAndFinite) {
    for (const ViewPoint c : {ViewPoint{0.0, 0.0, 0.0}, ViewPoint{0.1, -0.2, 0.3}, ViewPoint{0.0, 0.0, 1.0}}) {
        const SphereProjection s = projectSphere(c, 1.0, 200.0, {100.0, 100.0});  // D ≤ r (D = r included)
        EXPECT_EQ(s.kind, SphereClass::EyeInside) << c.x << " " << c.y << " " << c.z;
        EXPECT_TRUE(allFinite(s));
        EXPECT_DOUBLE_EQ(s.alpha(), std::numbers::pi / 2.0);
        EXPECT_TRUE(std::isinf(s.index2({100.0, 100.0})));
        const PixelRange all = pixelRange(s.bounds, 200, 200);
        EXPECT_EQ(all.count(), 200 * 200);  // the fallback covers the whole image
        const double F = halfRayFootprint(s, {100.5, 100.5});
        EXPECT_TRUE(std::isfinite(F));
        EXPECT_GT(F, 0.0);
        EXPECT_LE(F, Kernel::footprint(0.0) + 1e-12);
    }
}

TEST(Ellipse, StraddlingSphereFallbackBoundsAreConservative) {
    const double f = 150.0;
    const PixelCoord pp(100.0, 100.0);
    const ViewPoint cases[] = {{1.5, 0.3, 0.5}, {-2.0, 1.0, 0.0}, {0.0, 1.2, -0.4}, {1.1, 0.0, 1.0}, {0.5, 0.5, 1.0 + 1e-15}};
    for (const ViewPoint& c : cases) {
        const SphereProjection s = projectSphere(c, 1.0, f, pp);
        SCOPED_TRACE(testing::Message() << c.x << " " << c.y << " " << c.z);
        EXPECT_EQ(s.kind, SphereClass::Straddles);
        EXPECT_TRUE(allFinite(s));
        long hits = 0;
        for (int y = 0; y < 200; ++y)
            for (int x = 0; x < 200; ++x) {
                const PixelCoord p(x + 0.5, y + 0.5);
                const double F = halfRayFootprint(s, p);
                ASSERT_TRUE(std::isfinite(F));
                if (F <= 0.0) continue;
                ++hits;
                EXPECT_TRUE(p.x >= s.bounds.lo.x && p.x <= s.bounds.hi.x && p.y >= s.bounds.lo.y && p.y <= s.bounds.hi.y);
            }
        RecordProperty("straddle_hits", static_cast<int>(hits));
    }
}

TEST(Ellipse, BehindAndInvalidInputAreCulled) {
    const SphereProjection behind = projectSphere({0.0, 0.0, -5.0}, 1.0, 100.0, {0.0, 0.0});
    EXPECT_EQ(behind.kind, SphereClass::Behind);
    EXPECT_TRUE(behind.bounds.empty());
    EXPECT_EQ(halfRayFootprint(behind, {0.5, 0.5}), 0.0);
    EXPECT_TRUE(allFinite(behind));
    const double nan = std::nan("");
    EXPECT_EQ(projectSphere({nan, 0.0, 5.0}, 1.0, 100.0, {0.0, 0.0}).kind, SphereClass::Behind);
    EXPECT_EQ(projectSphere({0.0, 0.0, 5.0}, 0.0, 100.0, {0.0, 0.0}).kind, SphereClass::Behind);
    EXPECT_EQ(projectSphere({0.0, 0.0, 5.0}, 1.0, -1.0, {0.0, 0.0}).kind, SphereClass::Behind);
    EXPECT_TRUE(allFinite(projectSphere({nan, 0.0, 5.0}, 1.0, 100.0, {0.0, 0.0})));
}

TEST(Ellipse, BoundaryCaseCzEqualsRadiusStraddles) {
    const SphereProjection s = projectSphere({3.0, 0.0, 1.0}, 1.0, 100.0, {0.0, 0.0});
    EXPECT_EQ(s.kind, SphereClass::Straddles);  // cos²θ = sin²α exactly: a parabola
    EXPECT_TRUE(allFinite(s));
}

TEST(Ellipse, HalfRayFootprintEqualsFullFootprintForEllipses) {
    const SphereProjection s = projectSphere({1.0, -0.5, 6.0}, 0.8, 200.0, {50.0, 50.0});
    ASSERT_EQ(s.kind, SphereClass::Ellipse);
    for (double dx = -20.0; dx <= 20.0; dx += 2.5) {
        const PixelCoord p = s.centre + glm::dvec2(dx, 0.3 * dx);
        const double d = exactRayDistance(s, p);
        const double expected = d < 1.0 ? Kernel::footprint(d * Kernel::kRadius) : 0.0;
        EXPECT_NEAR(halfRayFootprint(s, p), expected, 1e-12);
    }
}

/// The affine ellipse→circle index is exact on-axis and approximate off-axis (DESIGN §3).
/// This measures max |reindex(i(p), α) − d_exact(p)| over the ellipse and REPORTS it.
TEST(Ellipse, AffineIndexErrorOffAxisIsMeasuredAndReported) {
    std::printf("affine-index error max|d(i(p),α) − d_exact(p)| over the ellipse (and in F, relative to F(0)):\n");
    EXPECT_EQ(projectSphere(ViewPoint(0.0, 0.0, 0.5), 1.0, 100.0, {0.0, 0.0}).affineIndexError(),
              std::numeric_limits<double>::infinity()) << "no ellipse, no affine index";
    std::printf("  theta\\alpha ");
    const double alphas[] = {0.5, 2.0, 5.0, 15.0, 30.0};
    for (double a : alphas) std::printf("%16.1f°", a);
    std::printf("\n");
    for (double theta : {0.0, 10.0, 20.0, 35.0}) {
        std::printf("  %5.1f°     ", theta);
        for (double alpha : alphas) {
            const double D = 10.0, r = D * std::sin(alpha * kDeg);
            const ViewPoint c = D * direction(theta, 30.0);
            const double f = 40.0 * std::sqrt(c.z * c.z - r * r) / r;
            const SphereProjection s = projectSphere(c, r, f, {0.0, 0.0});
            ASSERT_EQ(s.kind, SphereClass::Ellipse);
            double worstD = 0.0, worstF = 0.0;
            const PixelRange range = pixelRange(s.bounds);
            for (int y = range.y0; y <= range.y1; ++y)
                for (int x = range.x0; x <= range.x1; ++x) {
                    const PixelCoord p(x + 0.5, y + 0.5);
                    const double i2 = s.index2(p);
                    if (i2 > 1.0) continue;
                    const double dAffine = reindex(std::sqrt(i2), s.alpha());
                    const double dExact = std::min(exactRayDistance(s, p), 1.0);
                    worstD = std::max(worstD, std::abs(dAffine - dExact));
                    worstF = std::max(worstF, std::abs(Kernel::footprint(dAffine * Kernel::kRadius) -
                                                       Kernel::footprint(dExact * Kernel::kRadius)));
                }
            worstF /= Kernel::footprint(0.0);
            std::printf("  %7.2e (%6.4f)", worstD, worstF);
            char key[64];
            std::snprintf(key, sizeof key, "affine_d_error_theta%g_alpha%g", theta, alpha);
            RecordProperty(key, testing::PrintToString(worstD));
            if (theta == 0.0) {
                EXPECT_LT(worstD, 1e-9) << "the affine index must be exact on-axis";
            }
            // SphereProjection::affineIndexError() (tanθ·tanα) is what --footprint auto
            // thresholds: it must track the measured error within 20 % both ways.
            const double estimate = s.affineIndexError();
            EXPECT_NEAR(estimate, std::tan(theta * kDeg) * std::tan(alpha * kDeg), 1e-12);
            EXPECT_LE(worstD, 1.2 * estimate + 1e-9) << "theta " << theta << " alpha " << alpha;
            EXPECT_GE(worstD, 0.8 * estimate - 1e-9) << "theta " << theta << " alpha " << alpha;
        }
        std::printf("\n");
    }
}

}  // namespace
}  // namespace vdbsplat
