// tests/footprint/swan_test.cpp — Swan et al. 1997's stretched footprint (footprint/swan.h):
// never narrower than the pixel filter, the same total as the unstretched kernel (and so as
// the point, DESIGN §4), and untouched where the footprint is already wide enough.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/swan.h"
#include "pointfilter/point_filter.h"

namespace vdbsplat {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Camera testCamera() { return Camera({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, 40.0, 512, 512); }

ViewPoint at(double D, double theta, double phi = 0.7) {
    return D * glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

/// Σ over pixel centres of the exact-path deposit (closed-form footprint at the exact index of
/// the pulled-back pixel), σ per world unit.
double kernelSum(const ScreenKernel& k, const SphereProjection& e, double sigma, double h) {
    double sum = 0.0;
    for (int y = int(std::floor(k.bounds.lo.y)) - 1; y <= int(std::ceil(k.bounds.hi.y)) + 1; ++y)
        for (int x = int(std::floor(k.bounds.lo.x)) - 1; x <= int(std::ceil(k.bounds.hi.x)) + 1; ++x)
            sum += splatDepositExact(k, e, sigma, h, {x + 0.5, y + 0.5});
    return sum;
}

/// The support ellipse's minor semi-axis from its conic (largest eigenvalue of Q = 1/b²).
double minorSemiAxis(const glm::dmat2& Q) {
    const double tr = Q[0][0] + Q[1][1], det = glm::determinant(Q);
    const double lmax = 0.5 * tr + std::sqrt(std::max(0.25 * tr * tr - det, 0.0));
    return 1.0 / std::sqrt(lmax);
}

TEST(Swan, FootprintIsNeverNarrowerThanThePixelFilter) {
    const Camera cam = testCamera();
    for (const double vh : {1.0, 0.25})
        for (const double spacingPx : {0.02, 0.1, 0.3, 0.7, 1.0, 1.6, 3.0})
            for (const double thetaDeg : {0.0, 15.0, 35.0}) {
                const ViewPoint c = at(2.0, thetaDeg * kDeg);
                const double h = spacingPx * c.z / cam.focal();
                const SphereProjection e = projectSphere(cam, c, Kernel::kRadius * h);
                const ScreenKernel k = makeSwanKernel(e, vh);
                const double minorSigma = minorSemiAxis(k.conic) * Kernel::kSigma / Kernel::kRadius;
                EXPECT_GE(minorSigma, std::sqrt(vh) * (1.0 - 1e-9)) << spacingPx << " px, θ " << thetaDeg;
                EXPECT_NEAR(std::min(k.a, k.b) * Kernel::kSigma / Kernel::kRadius, std::max(std::sqrt(vh), std::min(e.a, e.b) * Kernel::kSigma / Kernel::kRadius), 1e-9);
            }
}

// The stretch is uniform (Swan): both axes by the same s, the ellipse's shape and centre kept,
// and s = 1 (the exact ellipse, amplitude 1) once the footprint is as wide as the filter.
TEST(Swan, StretchIsUniformAndOnlyForNarrowFootprints) {
    const Camera cam = testCamera();
    const ViewPoint c = at(2.0, 25 * kDeg);
    const SphereProjection small = projectSphere(cam, c, Kernel::kRadius * 0.2 * c.z / cam.focal());
    const ScreenKernel k = makeSwanKernel(small);
    const double s = swanStretch(small);
    EXPECT_GT(s, 5.0);
    EXPECT_NEAR(k.a / small.a, s, 1e-12);
    EXPECT_NEAR(k.b / small.b, s, 1e-12);
    EXPECT_NEAR(k.amplitude, 1.0 / (s * s), 1e-15);
    EXPECT_EQ(k.centre, small.centre);
    const SphereProjection big = projectSphere(cam, c, Kernel::kRadius * 4.0 * c.z / cam.focal());
    EXPECT_DOUBLE_EQ(swanStretch(big), 1.0);
    EXPECT_DOUBLE_EQ(makeSwanKernel(big).amplitude, 1.0);
    EXPECT_THROW(makeSwanKernel(projectSphere(cam, {0.0, 0.0, 0.01}, 0.1)), std::invalid_argument);
}

// Energy (DESIGN §4): the stretched kernel's deposits sum to the point's total.
TEST(Swan, DepositsSumToThePointsTotal) {
    const Camera cam = testCamera();
    const double sigma = 2.0;
    for (const double spacingPx : {0.05, 0.2, 0.5, 0.9})
        for (const double thetaDeg : {0.0, 20.0, 35.0}) {
            const ViewPoint c = at(2.0, thetaDeg * kDeg);
            const double h = spacingPx * c.z / cam.focal();
            const SphereProjection e = projectSphere(cam, c, Kernel::kRadius * h);
            const double ratio = kernelSum(makeSwanKernel(e), e, sigma, h) / pointDepositTotal(sigma, h, cam.focal(), c);
            EXPECT_NEAR(ratio, 1.0, 0.01) << spacingPx << " px, θ " << thetaDeg;
        }
}

}  // namespace
}  // namespace vdbsplat
