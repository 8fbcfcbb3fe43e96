// tests/footprint/ewa_test.cpp — EWA volume splatting's affine screen kernel (footprint/ewa.h,
// Zwicker et al. 2001) against slow, obvious oracles: a finite-difference Jacobian of
// the ray-space map and of the camera's projection, the energy rule (the point's total), and the
// exact perspective ellipse it approximates (equal on the axis as α → 0, not off the axis).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "footprint/ellipse.h"
#include "footprint/ewa.h"
#include "footprint/kernel.h"
#include "pointfilter/point_filter.h"

namespace vdbsplat {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Camera testCamera(int size = 512) { return Camera({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, 40.0, size, size); }

/// The view point at distance @p D, angle @p theta from the axis, in the direction @p phi around it.
ViewPoint at(double D, double theta, double phi = 0.3) {
    return D * glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

/// m(t) = (t0/t2, t1/t2, ‖t‖): the ray-space map of Zwicker et al. 2001.
glm::dvec3 raySpace(const glm::dvec3& t) { return {t.x / t.z, t.y / t.z, glm::length(t)}; }

TEST(Ewa, JacobianMatchesFiniteDifferencesOfTheRaySpaceMap) {
    for (const ViewPoint t : {ViewPoint(0.0, 0.0, 3.0), at(2.0, 20 * kDeg), at(0.7, 50 * kDeg, 2.1), ViewPoint(-1.5, 0.4, 0.9)}) {
        const glm::dmat3 J = ewaJacobian(t);
        const double e = 1e-6;
        for (int col = 0; col < 3; ++col) {
            glm::dvec3 d(0.0);
            d[col] = e;
            const glm::dvec3 fd = (raySpace(t + d) - raySpace(t - d)) / (2.0 * e);
            for (int row = 0; row < 3; ++row) EXPECT_NEAR(J[col][row], fd[row], 1e-7) << "row " << row << " col " << col;
        }
    }
}

// Σ = S·(J W V Wᵀ Jᵀ)₂ₓ₂·Sᵀ must be the covariance that the camera's own projection gives a
// small Gaussian to first order: Jp·V·Jpᵀ with Jp the finite-difference 2×3 Jacobian of
// Camera::project in view space (the pixel y axis points down: S = diag(f, −f)).
TEST(Ewa, ScreenVarianceIsTheProjectionsJacobianTimesTheKernelVariance) {
    const Camera cam = testCamera();
    const double s = 0.02;  // kernel standard deviation, world units
    for (const ViewPoint t : {ViewPoint(0.0, 0.0, 3.0), at(2.0, 20 * kDeg), at(0.7, 35 * kDeg, 2.1)}) {
        glm::dmat3x2 Jp(0.0);  // 3 columns, 2 rows
        const double e = 1e-6;
        for (int col = 0; col < 3; ++col) {
            glm::dvec3 d(0.0);
            d[col] = e;
            Jp[col] = (cam.project(t + d) - cam.project(t - d)) / (2.0 * e);
        }
        const glm::dmat2 expected = Jp * (s * s * glm::dmat3(1.0)) * glm::transpose(Jp);
        const glm::dmat2 got = ewaScreenVariance(t, worldToViewRotation(cam), s, cam.focal());
        for (int c = 0; c < 2; ++c)
            for (int r = 0; r < 2; ++r)
                EXPECT_NEAR(got[c][r], expected[c][r], 1e-6 * std::abs(expected[0][0])) << c << "," << r;
    }
}

// W enters as W V Wᵀ: for a rotation and an isotropic V it must change nothing.
TEST(Ewa, ViewRotationLeavesAnIsotropicKernelUnchanged) {
    const Camera tilted({1.0, 2.0, 3.0}, {0.3, -0.2, 0.5}, {0.0, 0.0, 1.0}, 40.0, 64, 64);
    const glm::dmat3 W = worldToViewRotation(tilted);
    const glm::dmat3 I = W * glm::transpose(W);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(I[c][r], c == r ? 1.0 : 0.0, 1e-12);
    const ViewPoint t = at(2.0, 25 * kDeg);
    const glm::dmat2 a = ewaRaySpaceVariance(t, W, 0.05), b = ewaRaySpaceVariance(t, glm::dmat3(1.0), 0.05);
    for (int c = 0; c < 2; ++c)
        for (int r = 0; r < 2; ++r) EXPECT_NEAR(a[c][r], b[c][r], 1e-15);
}

/// Σ over pixel centres of σ·h·F(R·i)·amplitude (the closed-form footprint, no table).
double ewaSum(const EwaKernel& k, double sigma, double h) {
    double sum = 0.0;
    for (int y = int(std::floor(k.bounds.lo.y)) - 1; y <= int(std::ceil(k.bounds.hi.y)) + 1; ++y)
        for (int x = int(std::floor(k.bounds.lo.x)) - 1; x <= int(std::ceil(k.bounds.hi.x)) + 1; ++x) {
            const double i2 = k.index2({x + 0.5, y + 0.5});
            if (i2 < 1.0) sum += sigma * h * Kernel::footprint(Kernel::kRadius * std::sqrt(i2)) * k.amplitude;
        }
    return sum;
}

// DESIGN §4: the splat's deposits sum to the point's total for the same voxel (σ·M·(f/z)²·(D/z)),
// off the axis too (det J = l/t2³ is Zwicker's normalisation), with and without the low-pass.
TEST(Ewa, DepositsSumToThePointsTotal) {
    const Camera cam = testCamera();
    const double sigma = 3.0;  // per world unit
    for (const double spacingPx : {0.3, 1.0, 3.0, 8.0})
        for (const double thetaDeg : {0.0, 10.0, 20.0, 35.0})
            for (const double vh : {kPrefilterVariance, 0.0}) {
                if (vh == 0.0 && spacingPx < 1.0) continue;  // unfiltered sub-pixel splats alias (that is `none`)
                const ViewPoint c = at(2.0, thetaDeg * kDeg);
                const double h = spacingPx * c.z / cam.focal();
                const EwaKernel k = makeEwaKernel(cam, c, h, Kernel::kSigma, Kernel::kRadius, vh);
                const double point = pointDepositTotal(sigma, h, cam.focal(), c);
                EXPECT_NEAR(ewaSum(k, sigma, h) / point, 1.0, 0.01)
                    << "spacing " << spacingPx << " θ " << thetaDeg << " V_h " << vh;
            }
}

// The low-pass adds V_h to Σ: the widened kernel's variance, and the amplitude √(det Σ/det Σ').
TEST(Ewa, LowPassAddsItsVarianceAndKeepsTheTotal) {
    const Camera cam = testCamera();
    const ViewPoint c = at(2.0, 30 * kDeg);
    const double h = 0.5 * c.z / cam.focal();
    const EwaKernel bare = makeEwaKernel(cam, c, h, Kernel::kSigma, Kernel::kRadius, 0.0);
    const EwaKernel wide = makeEwaKernel(cam, c, h, Kernel::kSigma, Kernel::kRadius, 1.0);
    EXPECT_NEAR(wide.variance[0][0] - bare.variance[0][0], 1.0, 1e-12);
    EXPECT_NEAR(wide.variance[1][1] - bare.variance[1][1], 1.0, 1e-12);
    EXPECT_NEAR(wide.variance[0][1], bare.variance[0][1], 1e-12);
    EXPECT_DOUBLE_EQ(bare.amplitude, 1.0);
    EXPECT_NEAR(wide.amplitude, std::sqrt(glm::determinant(bare.variance) / glm::determinant(wide.variance)), 1e-12);
    EXPECT_LT(wide.amplitude, 0.5);
}

/// Max |F_ewa − F_exact| / F(0) over the pixels of the exact ellipse's box (no low-pass: the
/// geometry alone), F_exact = the exact per-pixel footprint Kernel::footprint(R·d_exact).
double maxFootprintDifference(const Camera& cam, const ViewPoint& c, double h) {
    const SphereProjection e = projectSphere(cam, c, Kernel::kRadius * h);
    const EwaKernel k = makeEwaKernel(cam, c, h, Kernel::kSigma, Kernel::kRadius, 0.0);
    double worst = 0.0;
    const double lo = std::min(e.bounds.lo.x, k.bounds.lo.x), hi = std::max(e.bounds.hi.x, k.bounds.hi.x);
    const double loy = std::min(e.bounds.lo.y, k.bounds.lo.y), hiy = std::max(e.bounds.hi.y, k.bounds.hi.y);
    const double step = std::max((hi - lo) / 200.0, 0.05);
    for (double y = loy; y <= hiy; y += step)
        for (double x = lo; x <= hi; x += step) {
            const double d2 = exactRayDistance2(e, {x, y});
            const double exact = d2 < 1.0 ? Kernel::footprint(Kernel::kRadius * std::sqrt(d2)) : 0.0;
            const double i2 = k.index2({x, y});
            const double ewa = i2 < 1.0 ? Kernel::footprint(Kernel::kRadius * std::sqrt(i2)) * k.amplitude : 0.0;
            worst = std::max(worst, std::abs(ewa - exact));
        }
    return worst / Kernel::footprint(0.0);
}

// On the axis the affine approximation tends to the exact projection as α → 0 (the semi-axes
// differ by 1 − cos α); off the axis and close to the eye it does not (the exact ellipse is
// centred at the midpoint of A′B′, elongated by 1/(cos²θ − sin²α)). Measured (max |ΔF|/F(0),
// no low-pass): 8.3e−5 and 9.5e−4 on the axis at α = 0.29° and 2.9°; 0.0075 at θ = 20°, α = 3°;
// 0.050 at θ = 30°, α = 12°; 0.19 at θ = 45°, α = 20°.
TEST(Ewa, EqualsTheExactEllipseOnAxisAndDiffersOffAxisCloseUp) {
    const Camera cam = testCamera();
    const auto alphaH = [](double D, double alphaDeg) { return D * std::sin(alphaDeg * kDeg) / Kernel::kRadius; };
    const double onFar = maxFootprintDifference(cam, ViewPoint(0, 0, 4.0), alphaH(4.0, 0.29));
    const double onNear = maxFootprintDifference(cam, ViewPoint(0, 0, 4.0), alphaH(4.0, 2.9));
    const double offMid = maxFootprintDifference(cam, at(1.0, 20 * kDeg), alphaH(1.0, 3.0));
    const double offClose = maxFootprintDifference(cam, at(0.5, 30 * kDeg), alphaH(0.5, 12.0));
    const double offEdge = maxFootprintDifference(cam, at(0.5, 45 * kDeg), alphaH(0.5, 20.0));
    std::printf("  max |F_ewa - F_exact| / F(0): on-axis α 0.29° %.2e, 2.9° %.2e; θ 20° α 3° %.4f; "
                "θ 30° α 12° %.3f; θ 45° α 20° %.3f\n",
                onFar, onNear, offMid, offClose, offEdge);
    EXPECT_LT(onFar, 2e-4);
    EXPECT_LT(onNear, 2e-3);
    EXPECT_GT(onNear, 5.0 * onFar);  // the error grows like α²
    EXPECT_GT(offMid, 4.0 * onNear);
    EXPECT_GT(offClose, 0.03);
    EXPECT_GT(offEdge, 0.1);
}

TEST(Ewa, DegenerateInputGivesAnEmptyKernel) {
    const Camera cam = testCamera();
    EXPECT_EQ(makeEwaKernel(cam, ViewPoint(0.0, 0.0, -1.0), 0.01, Kernel::kSigma, Kernel::kRadius).amplitude, 0.0);
    EXPECT_EQ(makeEwaKernel(cam, ViewPoint(0.0, 0.0, 0.0), 0.01, Kernel::kSigma, Kernel::kRadius).amplitude, 0.0);
    EXPECT_TRUE(makeEwaKernel(cam, ViewPoint(0.0, 0.0, -1.0), 0.01, Kernel::kSigma, Kernel::kRadius).bounds.empty());
}

}  // namespace
}  // namespace vdbsplat
