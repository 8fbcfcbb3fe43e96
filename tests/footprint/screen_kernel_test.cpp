// tests/footprint/screen_kernel_test.cpp — the EWA-filtered splat kernel (DESIGN §4):
// widening keeps the total deposit, the conic and amplitude match V + V_h, the table
// path matches the exact path on-axis, and non-ellipses are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/screen_kernel.h"
#include "footprint/tables.h"

namespace vdbsplat {
namespace {

const Tables& tables() {
    static const Tables t = buildTables();  // test-local cache
    return t;
}

/// Σ over the kernel's pixels of the table-path deposit.
double tableTotal(const ScreenKernel& k, double sigma, double h) {
    const SplatShader shader = makeSplatShader(k, tables(), sigma, h);
    const PixelRange r = pixelRange(k.bounds);
    double sum = 0.0;
    for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) sum += splatDeposit(k, shader, {x + 0.5, y + 0.5});
    return sum;
}

SphereProjection offAxisSphere(double f) {
    return projectSphere({1.5, -0.8, 9.0}, 0.2, f, {300.5, 200.25});
}

TEST(ScreenKernel, ConicAndAmplitudeMatchVPlusVh) {
    const SphereProjection e = offAxisSphere(400.0);
    ASSERT_EQ(e.kind, SphereClass::Ellipse);
    const ScreenKernel k = makeScreenKernel(e);
    const double s = Kernel::kSigma / Kernel::kRadius;
    const glm::dvec2 u = e.u, v(-u.y, u.x);
    const glm::dmat2 V = (e.a * s) * (e.a * s) * glm::outerProduct(u, u) + (e.b * s) * (e.b * s) * glm::outerProduct(v, v);
    const glm::dmat2 Vw = V + glm::dmat2(kPrefilterVariance);
    EXPECT_NEAR(k.amplitude, std::sqrt(glm::determinant(V) / glm::determinant(Vw)), 1e-12);
    const glm::dmat2 Q = glm::inverse(Vw) * (s * s);  // support = std × R/s_g
    for (int c = 0; c < 2; ++c)
        for (int r = 0; r < 2; ++r) EXPECT_NEAR(k.conic[c][r], Q[c][r], 1e-12 * std::abs(Q[0][0]));
    EXPECT_NEAR(k.index2(k.centre + k.a * u), 1.0, 1e-12);
    EXPECT_NEAR(k.index2(k.centre + k.b * v), 1.0, 1e-12);
    EXPECT_GT(k.a, e.a);
    EXPECT_GT(k.b, e.b);
}

TEST(ScreenKernel, NoPrefilterIsTheExactEllipse) {
    const SphereProjection e = offAxisSphere(400.0);
    const ScreenKernel k = makeScreenKernel(e, 0.0);
    EXPECT_DOUBLE_EQ(k.amplitude, 1.0);
    for (const glm::dvec2 d : {glm::dvec2(3.0, 1.0), glm::dvec2(-2.0, 4.0), glm::dvec2(0.5, -7.0)})
        EXPECT_NEAR(k.index2(e.centre + d), e.index2(e.centre + d), 1e-12);
}

TEST(ScreenKernel, EwaTotalEqualsUnfilteredTotal) {
    for (double f : {150.0, 400.0, 1500.0}) {  // semi-axes ≈ 3.4, 9, 34 px
        const SphereProjection e = offAxisSphere(f);
        const double filtered = tableTotal(makeScreenKernel(e), 2.0, 0.1);
        const double unfiltered = tableTotal(makeScreenKernel(e, 0.0), 2.0, 0.1);
        std::printf("f %6.0f: a %.2f px, EWA total / unfiltered total = %.6f\n", f, e.a, filtered / unfiltered);
        EXPECT_NEAR(filtered / unfiltered, 1.0, 5e-3) << "f " << f;
    }
}

TEST(ScreenKernel, BoundsContainTheSupport) {
    const ScreenKernel k = makeScreenKernel(offAxisSphere(400.0));
    for (int n = 0; n < 360; ++n) {
        const double t = n * std::numbers::pi / 180.0;
        const glm::dvec2 p = k.centre + k.a * std::cos(t) * k.u + k.b * std::sin(t) * glm::dvec2(-k.u.y, k.u.x);
        EXPECT_GE(p.x, k.bounds.lo.x - 1e-9);
        EXPECT_LE(p.x, k.bounds.hi.x + 1e-9);
        EXPECT_GE(p.y, k.bounds.lo.y - 1e-9);
        EXPECT_LE(p.y, k.bounds.hi.y + 1e-9);
    }
}

TEST(ScreenKernel, TablePathMatchesExactPathOnAxis) {
    for (double alphaDeg : {1.0, 10.0, 40.0}) {
        const double D = 6.0, r = D * std::sin(alphaDeg * std::numbers::pi / 180.0);
        const SphereProjection e = projectSphere({0.0, 0.0, D}, r, 30.0 / std::tan(alphaDeg * std::numbers::pi / 180.0), {50.0, 50.0});
        const ScreenKernel k = makeScreenKernel(e, 0.0);
        const SplatShader shader = makeSplatShader(k, tables(), 1.0, 1.0);
        double worst = 0.0;
        const PixelRange range = pixelRange(k.bounds);
        for (int y = range.y0; y <= range.y1; ++y)
            for (int x = range.x0; x <= range.x1; ++x) {
                const PixelCoord p(x + 0.5, y + 0.5);
                if (k.index2(p) > 0.999) continue;  // the rim: in/out differs by rounding
                worst = std::max(worst, std::abs(splatDeposit(k, shader, p) - splatDepositExact(k, e, 1.0, 1.0, p)));
            }
        EXPECT_LT(worst, 2e-4 * Kernel::footprint(0.0)) << "alpha " << alphaDeg;
    }
}

TEST(ScreenKernel, FastExactPathMatchesClosedFormExactPathOffAxis) {
    const SphereProjection e = projectSphere({2.5, 1.0, 6.0}, 1.2, 300.0, {10.0, 20.0});  // θ ≈ 24°, α ≈ 10°
    ASSERT_EQ(e.kind, SphereClass::Ellipse);
    const ScreenKernel k = makeScreenKernel(e);
    const SplatShader shader = makeSplatShader(k, tables(), 1.0, 1.0);
    double worstFast = 0.0, worstTable = 0.0;
    const PixelRange range = pixelRange(k.bounds);
    for (int y = range.y0; y <= range.y1; ++y)
        for (int x = range.x0; x <= range.x1; ++x) {
            const PixelCoord p(x + 0.5, y + 0.5);
            const double exact = splatDepositExact(k, e, 1.0, 1.0, p);
            const double d2 = exactIndexD2(k, e, p);
            const double fast = d2 < 1.0 ? shader.depositAtD2(static_cast<float>(d2)) : 0.0;
            worstFast = std::max(worstFast, std::abs(fast - exact));
            worstTable = std::max(worstTable, std::abs(splatDeposit(k, shader, p) - exact));
        }
    const double peak = Kernel::footprint(0.0) * k.amplitude;
    std::printf("off-axis splat (theta %.1f°, alpha %.1f°): max |table − exact| / peak = %.4f, "
                "max |fast exact − exact| / peak = %.2e\n",
                e.theta() * 180.0 / std::numbers::pi, e.alpha() * 180.0 / std::numbers::pi, worstTable / peak, worstFast / peak);
    EXPECT_LT(worstFast, 2e-4 * peak);
    EXPECT_GT(worstTable, 10.0 * worstFast);  // the affine index is the dominant error off-axis
}

// The compositor's float form of the exact index (d² from the conic's float i² and the map's w)
// against the double exactIndexD2, from near the axis to far off it, small and large kernels,
// near and far, with the low-pass widening and without.
TEST(ScreenKernel, ExactIndexMapMatchesExactIndexD2) {
    struct Case {
        ViewPoint c;
        double r, f;
    };
    const Case cases[] = {
        {{2.5, 1.0, 6.0}, 1.2, 300.0},      // θ ≈ 24°, α ≈ 10°
        {{-40.0, 25.0, 90.0}, 2.0, 500.0},  // θ ≈ 28°, α ≈ 1°
        {{0.3, -0.2, 4.0}, 2.0, 150.0},     // near the axis, α = 30°
        {{150.0, 80.0, 400.0}, 2.0, 1000.0},// far: α ≈ 0.26°, spacing ≈ 2 px
    };
    for (const Case& cs : cases) {
        for (const double prefilter : {kPrefilterVariance, 0.0}) {
            const SphereProjection e = projectSphere(cs.c, cs.r, cs.f, {200.0, 200.0});
            ASSERT_EQ(e.kind, SphereClass::Ellipse);
            const ScreenKernel k = makeScreenKernel(e, prefilter);
            // The float centre and conic, as the compositor has them; the map from the double
            // centre, as makeSplat makes it. The loop's δ is measured from the float centre, so the
            // splat it draws is the kernel moved by their difference (< 2⁻²⁴ of the centre's
            // coordinates, as on the table path): d² is compared at the moved pixel.
            const glm::vec2 centre(k.centre);
            const float qxx = float(k.conic[0][0]), qxy = float(k.conic[0][1]), qyy = float(k.conic[1][1]);
            const ExactIndexMap map = makeExactIndexMap(k, e, k.centre);
            double worst = 0.0;
            int inside = 0;
            const PixelRange range = pixelRange(k.bounds);
            for (int y = range.y0; y <= range.y1; ++y)
                for (int x = range.x0; x <= range.x1; ++x) {
                    const float dx = float(x) + 0.5f - centre.x, dy = float(y) + 0.5f - centre.y;
                    const float i2 = qxx * dx * dx + 2.f * qxy * dx * dy + qyy * dy * dy;
                    if (!(i2 < 1.f)) continue;
                    const double d2 = exactIndexD2(k, e, k.centre + PixelCoord(dx, dy));
                    if (!(d2 < 1.0)) continue;  // the last bit of the border
                    ++inside;
                    const float fast = map.d2(i2, dx, dy);
                    EXPECT_LT(fast, 1.f);
                    worst = std::max(worst, std::abs(double(fast) - d2));
                }
            std::printf("  theta %5.1f° alpha %5.2f° V %.2f: %5d pixels, max |d²_map − d²_exact| = %.2e\n",
                        e.theta() * 180.0 / std::numbers::pi, e.alpha() * 180.0 / std::numbers::pi, prefilter, inside, worst);
            EXPECT_GT(inside, 3);
            EXPECT_LT(worst, 5e-7);
        }
    }
}

TEST(ScreenKernel, NonEllipsesAreRefused) {
    EXPECT_THROW(makeScreenKernel(projectSphere({0.0, 0.0, 0.5}, 1.0, 100.0, {0.0, 0.0})), std::invalid_argument);
    EXPECT_THROW(makeScreenKernel(projectSphere({3.0, 0.0, 0.5}, 1.0, 100.0, {0.0, 0.0})), std::invalid_argument);
    EXPECT_THROW(makeScreenKernel(projectSphere({0.0, 0.0, -5.0}, 1.0, 100.0, {0.0, 0.0})), std::invalid_argument);
}

}  // namespace
}  // namespace vdbsplat
