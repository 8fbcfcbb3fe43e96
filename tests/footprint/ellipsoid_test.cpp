// tests/footprint/ellipsoid_test.cpp — the exact projection of a kernel ellipsoid
// (footprint/ellipsoid.h): its conic against the brute-force oracle (pixel rays meeting the
// world-space quadric), the sphere case against DESIGN §2's ellipse, the index-space distance
// and its ExactIndexMap, the half-ray fallback, and the singular values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "footprint/ellipsoid.h"
#include "footprint/kernel.h"

namespace vdbsplat {
namespace {

constexpr double kF = 400.0;
const PixelCoord kPrincipal(200.0, 150.0);

glm::dmat3 rotation(double angle, glm::dvec3 axis) {
    axis = glm::normalize(axis);
    const double c = std::cos(angle), s = std::sin(angle);
    const glm::dmat3 K(glm::dvec3(0, axis.z, -axis.y), glm::dvec3(-axis.z, 0, axis.x), glm::dvec3(axis.y, -axis.x, 0));
    return glm::dmat3(1.0) + s * K + (1 - c) * K * K;
}

/// Anisotropic (1, 1, 2.5), rotated, and sheared shapes (world units per index unit).
std::vector<glm::dmat3> shapes() {
    const glm::dmat3 stretch(glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 2.5));
    glm::dmat3 shear(1.0);
    shear[1][0] = 0.6;  // index y → world x
    shear[2][1] = -0.4;
    return {stretch, rotation(0.7, {1, 2, 0.5}) * stretch, rotation(-1.1, {0.3, -1, 2}) * shear * 0.8,
            glm::dmat3(glm::dvec3(0.5, 0, 0), glm::dvec3(0, 2.0, 0), glm::dvec3(0, 0, 1.0))};
}

std::vector<ViewPoint> centres() {
    return {{0.0, 0.0, 30.0}, {6.0, -4.0, 25.0}, {-9.0, 7.0, 14.0}, {1.5, 2.0, 9.0}, {20.0, 0.5, 40.0}};
}

glm::dvec3 ray(const PixelCoord& p) { return {(p.x - kPrincipal.x) / kF, -(p.y - kPrincipal.y) / kF, 1.0}; }

// Every pixel ray of the (widened) bounding box: inside the projected conic exactly when the
// ray meets the quadric, except within 1e−6 of the silhouette (rounding).
TEST(Ellipsoid, ConicMatchesBruteForceRays) {
    int tested = 0, inside = 0;
    for (const glm::dmat3& m : shapes()) {
        const VoxelShape shape = VoxelShape::of(m);
        EXPECT_FALSE(shape.sphere);
        for (const ViewPoint& c : centres()) {
            const EllipsoidProjection e = projectEllipsoid(shape, c, kF, kPrincipal);
            ASSERT_EQ(e.kind, SphereClass::Ellipse) << c.x << "," << c.y << "," << c.z;
            const PixelBox& b = e.ellipse.bounds;
            const double pad = 3.0, step = std::max(0.25, (b.hi.x - b.lo.x) / 120.0);
            for (double y = b.lo.y - pad; y <= b.hi.y + pad; y += step)
                for (double x = b.lo.x - pad; x <= b.hi.x + pad; x += step) {
                    const PixelCoord p(x, y);
                    const double i2 = e.ellipse.index2(p);
                    const double d2 = ellipsoidRayDistance2(shape, c, ray(p));
                    const bool hit = rayHitsEllipsoid(shape, c, ray(p));
                    if (std::abs(d2 - 1.0) < 1e-6) continue;
                    ++tested;
                    inside += hit;
                    ASSERT_EQ(i2 <= 1.0, hit) << "conic at " << x << "," << y << " i2 " << i2;
                    ASSERT_EQ(d2 <= 1.0, hit) << "distance at " << x << "," << y << " d2 " << d2;
                    if (hit) {
                        ASSERT_TRUE(b.lo.x <= x && x <= b.hi.x && b.lo.y <= y && y <= b.hi.y) << "outside bounds";
                    }
                }
        }
    }
    EXPECT_GT(tested, 20000);
    EXPECT_GT(inside, 2000);
}

// The ray–centre distance in index space against the line transformed explicitly.
TEST(Ellipsoid, IndexSpaceDistanceIsTheDistanceOfTheTransformedLine) {
    for (const glm::dmat3& m : shapes()) {
        const VoxelShape shape = VoxelShape::of(m);
        for (const ViewPoint& c : centres())
            for (const glm::dvec3 v : {glm::dvec3(0.1, -0.05, 1.0), glm::dvec3(c / c.z) + glm::dvec3(0.01, 0.02, 0.0)}) {
                const glm::dvec3 o = shape.N * (-c), d = glm::normalize(shape.N * v);
                const glm::dvec3 closest = o - glm::dot(o, d) * d;  // the centre is the index origin
                const double want = glm::dot(closest, closest) / (Kernel::kRadius * Kernel::kRadius);
                EXPECT_NEAR(ellipsoidRayDistance2(shape, c, v), want, 1e-9 * std::max(1.0, want));
            }
    }
}

// M = h·(rotation): the ellipse of DESIGN §2 (projectSphere), whatever the rotation.
TEST(Ellipsoid, SphereShapeGivesDesignEllipse) {
    for (double h : {1.0, 0.37}) {
        const VoxelShape shape = VoxelShape::of(h * rotation(0.9, {1, 1, 1}));
        EXPECT_TRUE(shape.sphere);
        EXPECT_NEAR(shape.h, h, 1e-12);
        for (const ViewPoint& c : centres()) {
            const ViewPoint cc = c * h;
            const EllipsoidProjection e = projectEllipsoid(shape, cc, kF, kPrincipal);
            const SphereProjection s = projectSphere(cc, Kernel::kRadius * h, kF, kPrincipal);
            ASSERT_EQ(e.kind, SphereClass::Ellipse);
            ASSERT_TRUE(s.isEllipse());
            EXPECT_NEAR(e.ellipse.a, s.a, 1e-7 * s.a);
            EXPECT_NEAR(e.ellipse.b, s.b, 1e-7 * s.a);
            EXPECT_NEAR(e.ellipse.centre.x, s.centre.x, 1e-7 * s.a);
            EXPECT_NEAR(e.ellipse.centre.y, s.centre.y, 1e-7 * s.a);
            if (s.rho > 1e-9) {
                EXPECT_NEAR(std::abs(glm::dot(e.ellipse.u, s.u)), 1.0, 1e-9);
            }
            EXPECT_NEAR(e.lengthScale, h, 1e-12);
        }
    }
}

// The compositor's exact-index map in index space reproduces the exact distance (no widening:
// the pullback is the identity), in float.
TEST(Ellipsoid, IndexMapMatchesTheExactDistance) {
    for (const glm::dmat3& m : shapes()) {
        const VoxelShape shape = VoxelShape::of(m);
        for (const ViewPoint& c : centres()) {
            const EllipsoidProjection e = projectEllipsoid(shape, c, kF, kPrincipal);
            const ScreenKernel k = makeScreenKernel(e.ellipse, 0.0);
            const PixelCoord origin = k.centre;
            const ExactIndexMap map = makeEllipsoidIndexMap(k, e, shape, origin);
            for (double dy = -k.b; dy <= k.b; dy += k.b / 7)
                for (double dx = -k.a; dx <= k.a; dx += k.a / 7) {
                    const double want = ellipsoidRayDistance2(shape, c, ray(origin + PixelCoord(dx, dy)));
                    if (want > 1.0) continue;
                    const float i2 = float(k.index2(origin + PixelCoord(dx, dy)));
                    EXPECT_NEAR(map.d2(i2, float(dx), float(dy)), want, 2e-5);
                }
        }
    }
}

// The half-ray deposit of a kernel in front of the eye is its full line integral: F(d·R)
// times the world length per index length along the ray, over h.
TEST(Ellipsoid, HalfRayDepositInFrontIsTheFullChord) {
    for (const glm::dmat3& m : shapes()) {
        const VoxelShape shape = VoxelShape::of(m);
        for (const ViewPoint& c : centres()) {
            const glm::dvec3 v = c / c.z + glm::dvec3(0.003, -0.002, 0.0);
            const double d2 = ellipsoidRayDistance2(shape, c, v);
            const double want = Kernel::footprint(std::sqrt(d2) * Kernel::kRadius) * shape.lengthAlong(v) / shape.h;
            EXPECT_NEAR(ellipsoidHalfRayDeposit(shape, c, v), want, 1e-9);
        }
        // Eye at the centre: half of the chord through it.
        const glm::dvec3 v(0.2, 0.1, 1.0);
        EXPECT_NEAR(ellipsoidHalfRayDeposit(shape, glm::dvec3(0.0), v),
                    0.5 * Kernel::footprint(0.0) * shape.lengthAlong(v) / shape.h, 1e-9);
    }
}

TEST(Ellipsoid, ClassesAtTheEye) {
    const VoxelShape shape = VoxelShape::of(shapes()[1]);
    EXPECT_EQ(projectEllipsoid(shape, {0.0, 0.0, -20.0}, kF, kPrincipal).kind, SphereClass::Behind);
    EXPECT_EQ(projectEllipsoid(shape, {0.1, 0.0, 0.2}, kF, kPrincipal).kind, SphereClass::EyeInside);
    const EllipsoidProjection s = projectEllipsoid(shape, {8.0, 0.0, 1.0}, kF, kPrincipal);
    EXPECT_EQ(s.kind, SphereClass::Straddles);
    EXPECT_LT(s.ellipse.bounds.lo.x, s.ellipse.bounds.hi.x);
}

TEST(Ellipsoid, SingularValuesOfStretchedAndRotatedMaps) {
    const glm::dvec3 s = singularValues(rotation(0.4, {1, -2, 3}) * glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 2.5, 0),
                                                                                  glm::dvec3(0, 0, 0.5)));
    EXPECT_NEAR(s.x, 2.5, 1e-12);
    EXPECT_NEAR(s.y, 1.0, 1e-12);
    EXPECT_NEAR(s.z, 0.5, 1e-12);
    const VoxelShape k = VoxelShape::of(glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 2.5)));
    EXPECT_NEAR(k.volume, 2.5, 1e-12);
    EXPECT_NEAR(k.h, std::cbrt(2.5), 1e-12);
    EXPECT_NEAR(k.lengthAlong({0, 0, 1}), 2.5, 1e-12);
}

}  // namespace
}  // namespace vdbsplat
