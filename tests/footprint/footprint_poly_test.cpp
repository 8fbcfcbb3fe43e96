// tests/footprint/footprint_poly_test.cpp — the vector loop's polynomial footprint against the
// closed form (Kernel::footprint through the corrected reindex, DESIGN §3) and the tables.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "footprint/footprint_poly.h"
#include "footprint/kernel.h"
#include "footprint/tables.h"

namespace vdbsplat {
namespace {

const FootprintPolynomials& poly() {
    static const FootprintPolynomials p = FootprintPolynomials::build();
    return p;
}

// The bound footprint_poly.h states, over t ∈ [0, 1) and every α up to 15°.
TEST(FootprintPoly, WithinTheStatedBoundOfTheClosedForm) {
    const double err = poly().measureError();
    std::printf("  max |F_poly − F| / F(0) = %.3g (bound %.1g)\n", err, FootprintPolynomials::kErrorBound);
    EXPECT_LT(err, FootprintPolynomials::kErrorBound);
}

// Spot values: F(0) on the axis row; the silhouette goes to 0; α = 10° at i = 0.5 through the
// reindex d² = t / (cos²α + t sin²α).
TEST(FootprintPoly, PinnedValues) {
    const double f0 = Kernel::footprint(0.0);
    EXPECT_NEAR(FootprintPolynomials::evaluate(poly().axisRow(), 0.f), f0, FootprintPolynomials::kErrorBound * f0);
    EXPECT_EQ(FootprintPolynomials::evaluate(poly().axisRow(), 1.f), 0.f);
    EXPECT_LT(FootprintPolynomials::evaluate(poly().axisRow(), 0.9999f), 0.02 * f0);
    const double a = 10.0 * std::numbers::pi / 180.0, s2 = std::sin(a) * std::sin(a), t = 0.25;
    const double d2 = t / ((1.0 - s2) + t * s2);
    EXPECT_NEAR(FootprintPolynomials::evaluate(poly().row(s2), float(t)), Kernel::footprint(Kernel::kRadius * std::sqrt(d2)),
                FootprintPolynomials::kErrorBound * f0);
}

// The polynomial and the two-table path (the oracle) agree to within both their errors.
TEST(FootprintPoly, AgreesWithTheTablePath) {
    const Tables tables = buildTables();
    double worst = 0.0;
    for (int ia = 0; ia <= 30; ++ia) {
        const double alpha = 15.0 * ia / 30.0 * std::numbers::pi / 180.0;
        const auto row = tables.reindex.row(alpha);
        const auto c = poly().row(std::sin(alpha) * std::sin(alpha));
        for (int k = 0; k < 1000; ++k) {
            const float t = float(k) / 1000.f;
            worst = std::max(worst, double(std::abs(FootprintPolynomials::evaluate(c, t) -
                                                    tables.footprint.lookupD2(row.d2(t)))));
        }
    }
    EXPECT_LT(worst / Kernel::footprint(0.0), 2e-5);
}

// peak() bounds every row's polynomial over all t (and so every splat's row, a convex combination
// of two): the splat loop's opacity series are chosen from it (composite/splat_raster.h).
TEST(FootprintPoly, PeakBoundsEveryRow) {
    float highest = 0.f;
    for (int k = 0; k <= 400; ++k) {
        const double s2 = poly().sin2Max() * k / 400.0;
        const auto c = poly().row(s2);
        for (int j = 0; j <= 4096; ++j) highest = std::max(highest, FootprintPolynomials::evaluate(c, float(j) / 4096.f));
    }
    EXPECT_GE(poly().peak(), highest);
    EXPECT_LT(poly().peak(), 1.002f * highest);  // a tight bound: a loose one would send splats to longer series
}

TEST(FootprintPoly, CoversOnlyItsRange) {
    EXPECT_TRUE(poly().covers(0.0));
    EXPECT_TRUE(poly().covers(poly().sin2Max()));
    EXPECT_FALSE(poly().covers(poly().sin2Max() * 1.01));
    EXPECT_FALSE(poly().covers(-1e-3));
}

}  // namespace
}  // namespace vdbsplat
