// tests/camera/test_camera.cpp — the pinhole camera (camera/camera.h) against an
// independent brute-force pinhole built by hand (view matrix from eye/look-at/up,
// projection from the fov): projection, unprojection, pixel y down / view y up,
// explicit eye/look-at/up, the default framing (centre, corners, 80% sphere, --distance)
// and every validation error. Plus the framing of a rotated, translated, half-voxel grid
// through render's cameraFor (index→world itself is covered in tests/volume/test_grid.cpp).
#include <gtest/gtest.h>

#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "camera/camera.h"
#include "render/render.h"
#include "util/error.h"
#include "volume/grid.h"
#include "support/error_of.h"

namespace vdbsplat {
namespace {

using test::errorOf;

constexpr double kPi = std::numbers::pi;

bool has(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

/// A pinhole camera written out as two 4×4 matrices, independently of camera.cpp:
/// a right-handed view matrix (camera looks down −z, y up, x right) and a
/// perspective matrix to normalised device coordinates, then the viewport map with
/// pixel y down. The pixel of a world point is what an OpenGL pipeline would give.
struct BruteForcePinhole {
    glm::dmat4 view{1.0}, proj{1.0};
    int width, height;

    BruteForcePinhole(glm::dvec3 eye, glm::dvec3 at, glm::dvec3 up, double fovDeg, int w, int h)
        : width(w), height(h) {
        const glm::dvec3 f = glm::normalize(at - eye);
        const glm::dvec3 s = glm::normalize(glm::cross(f, up));
        const glm::dvec3 u = glm::cross(s, f);
        // Rows s, u, −f; column 3 the translation −R·eye (glm is column-major: m[col][row]).
        view = glm::dmat4(1.0);
        for (int c = 0; c < 3; ++c) {
            view[c][0] = s[c];
            view[c][1] = u[c];
            view[c][2] = -f[c];
        }
        view[3][0] = -glm::dot(s, eye);
        view[3][1] = -glm::dot(u, eye);
        view[3][2] = glm::dot(f, eye);
        const double t = 1.0 / std::tan(0.5 * fovDeg * kPi / 180.0), aspect = double(w) / double(h);
        const double n = 0.01, fa = 1000.0;
        proj = glm::dmat4(0.0);
        proj[0][0] = t / aspect;
        proj[1][1] = t;
        proj[2][2] = -(fa + n) / (fa - n);
        proj[2][3] = -1.0;
        proj[3][2] = -2.0 * fa * n / (fa - n);
    }
    glm::dvec2 pixel(const glm::dvec3& p) const {
        const glm::dvec4 clip = proj * view * glm::dvec4(p, 1.0);
        const glm::dvec2 ndc(clip.x / clip.w, clip.y / clip.w);
        return {0.5 * (ndc.x + 1.0) * width, 0.5 * (1.0 - ndc.y) * height};
    }
};

PixelCoord pixelOf(const Camera& c, const glm::dvec3& world) { return c.project(c.toView(world)); }

TEST(Camera, HandBuiltViewMatrixMatchesGlmLookAt) {
    const glm::dvec3 eye(3, -4, 2.5), at(0.5, 1, -1), up(0.1, 0.2, 1);
    const BruteForcePinhole b(eye, at, up, 40, 64, 48);
    const glm::dmat4 ref = glm::lookAt(eye, at, up);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(b.view[c][r], ref[c][r], 1e-12) << c << "," << r;
}

TEST(Camera, ProjectionMatchesBruteForcePinhole) {
    struct View {
        glm::dvec3 eye, at, up;
        double fov;
        int w, h;
    };
    const View views[] = {
        {{3, -4, 2.5}, {0.5, 1, -1}, {0.1, 0.2, 1}, 40, 64, 48},
        {{-10, 2, 0}, {0, 0, 0}, {0, 1, 0}, 30, 400, 400},
        {{0.2, 0.3, 50}, {0, 0, 0}, {0, 1, 0}, 12, 300, 500},  // looking straight down −z
        {{100, 200, -300}, {101, 199, -298}, {0, 0, 1}, 120, 17, 9},
    };
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const View& v : views) {
        const Camera cam(v.eye, v.at, v.up, v.fov, v.w, v.h);
        const BruteForcePinhole b(v.eye, v.at, v.up, v.fov, v.w, v.h);
        const double reach = glm::length(v.at - v.eye);
        int tested = 0;
        for (int k = 0; k < 200; ++k) {
            const glm::dvec3 p = v.at + 0.5 * reach * glm::dvec3(u(rng), u(rng), u(rng));
            if (cam.toView(p).z < 1e-3 * reach) continue;  // behind or at the eye
            const glm::dvec2 expect = b.pixel(p), got = pixelOf(cam, p);
            EXPECT_NEAR(got.x, expect.x, 1e-8 * std::max(1.0, std::abs(expect.x)));
            EXPECT_NEAR(got.y, expect.y, 1e-8 * std::max(1.0, std::abs(expect.y)));
            ++tested;
        }
        EXPECT_GT(tested, 100);
    }
}

TEST(Camera, LookAtIsThePrincipalPointAndPixelCentresAreHalfIntegers) {
    const Camera cam({1, 2, 3}, {4, -1, 0}, {0, 0, 1}, 30, 5, 7);
    const PixelCoord c = pixelOf(cam, {4, -1, 0});
    EXPECT_NEAR(c.x, 2.5, 1e-12);  // the centre of pixel (2, 3) of a 5×7 image
    EXPECT_NEAR(c.y, 3.5, 1e-12);
    EXPECT_EQ(cam.principal(), PixelCoord(2.5, 3.5));
    // Vertical fov: the top edge of the image is at half the fov above the axis.
    EXPECT_NEAR(cam.focal(), 3.5 / std::tan(15.0 * kPi / 180.0), 1e-9);
    const glm::dvec3 top = cam.worldRay({2.5, 0.0});
    EXPECT_NEAR(std::acos(glm::dot(top, cam.forward())) * 180.0 / kPi, 15.0, 1e-9);
}

TEST(Camera, ProjectUnprojectRoundTrip) {
    const Camera cam({-3, 7, 2}, {0.5, 0.25, -0.5}, {0, 0, 1}, 50, 320, 200);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    for (int k = 0; k < 100; ++k) {
        const glm::dvec3 p = cam.lookAt() + glm::dvec3(u(rng), u(rng), u(rng));
        const ViewPoint v = cam.toView(p);
        ASSERT_GT(v.z, 0.0);
        const PixelCoord px = cam.project(v);
        // Back: the view ray through the pixel, scaled to the point's depth, rotated to world.
        const glm::dvec3 back = cam.eye() + cam.viewToWorldDir(cam.viewRay(px) * v.z);
        EXPECT_NEAR(glm::length(back - p), 0.0, 1e-9);
        // The unit world ray through the pixel points at p.
        EXPECT_NEAR(glm::dot(cam.worldRay(px), glm::normalize(p - cam.eye())), 1.0, 1e-12);
    }
    // And from pixels: pixel → ray → point at depth 5 → pixel.
    for (const PixelCoord px : {PixelCoord(0, 0), PixelCoord(319.5, 0.5), PixelCoord(160, 100), PixelCoord(17.25, 190)}) {
        const glm::dvec3 p = cam.eye() + cam.viewToWorldDir(cam.viewRay(px) * 5.0);
        const PixelCoord again = pixelOf(cam, p);
        EXPECT_NEAR(again.x, px.x, 1e-9);
        EXPECT_NEAR(again.y, px.y, 1e-9);
    }
}

TEST(Camera, PixelYDownViewYUpXRight) {
    const Camera cam({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 30, 100, 100);
    // World +z (the up vector) is view +y and pixel −y.
    EXPECT_GT(cam.toView({0, 0, 1}).y, 0.0);
    EXPECT_LT(pixelOf(cam, {0, 0, 1}).y, 50.0);
    EXPECT_GT(pixelOf(cam, {0, 0, -1}).y, 50.0);
    // Looking along +y with z up, +x is to the right (right-handed).
    EXPECT_GT(cam.toView({1, 0, 0}).x, 0.0);
    EXPECT_GT(pixelOf(cam, {1, 0, 0}).x, 50.0);
    // The top row's rays point up in view space, the bottom row's down.
    EXPECT_GT(cam.viewRay({50, 0}).y, 0.0);
    EXPECT_LT(cam.viewRay({50, 100}).y, 0.0);
    EXPECT_GT(cam.worldRay({50, 0}).z, 0.0);
    // Depth is positive in front of the eye.
    EXPECT_NEAR(cam.toView({0, 0, 0}).z, 10.0, 1e-12);
}

TEST(Camera, ExplicitEyeLookAtUpAreHonoured) {
    CameraSpec spec;
    spec.hasEye = true;
    spec.eye = {5, 6, 7};
    spec.lookAt = {-1, 2, 0.5};
    spec.up = {0, 3, 0};  // not unit, not perpendicular to the view direction
    spec.fovDeg = 42;
    spec.width = 120;
    spec.height = 80;
    const Camera cam = makeCamera(spec, {-100, -100, -100}, {100, 100, 100});  // the box is ignored
    EXPECT_EQ(cam.eye(), spec.eye);
    EXPECT_EQ(cam.lookAt(), spec.lookAt);
    EXPECT_EQ(cam.width(), 120);
    EXPECT_EQ(cam.height(), 80);
    EXPECT_EQ(cam.fovDeg(), 42);
    EXPECT_NEAR(glm::length(cam.forward() - glm::normalize(spec.lookAt - spec.eye)), 0.0, 1e-12);
    // up: unit, perpendicular to forward, in the plane of forward and the requested up, on its side.
    EXPECT_NEAR(glm::length(cam.up()), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(cam.up(), cam.forward()), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(cam.up(), glm::normalize(glm::cross(cam.forward(), spec.up))), 0.0, 1e-12);
    EXPECT_GT(glm::dot(cam.up(), spec.up), 0.0);
    EXPECT_NEAR(glm::length(cam.right() - glm::normalize(glm::cross(cam.forward(), spec.up))), 0.0, 1e-12);
    const PixelCoord c = pixelOf(cam, spec.lookAt);
    EXPECT_NEAR(c.x, 60.0, 1e-9);
    EXPECT_NEAR(c.y, 40.0, 1e-9);
    EXPECT_TRUE(has(cam.describe(), "eye 5,6,7 look-at -1,2,0.5")) << cam.describe();
    EXPECT_TRUE(has(cam.describe(), "fov 42 size 120x80")) << cam.describe();
}

/// Max distance (px) from the image centre of the projected bounding sphere's
/// silhouette, along x and along y, by dense sampling of the sphere's surface.
glm::dvec2 sphereExtent(const Camera& cam, const glm::dvec3& centre, double radius) {
    glm::dvec2 ext(0.0);
    const int n = 181;
    for (int i = 0; i <= n; ++i) {
        const double theta = kPi * i / n;
        for (int j = 0; j < 2 * n; ++j) {
            const double phi = kPi * j / n;
            const glm::dvec3 p = centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi),
                                                              std::sin(theta) * std::sin(phi), std::cos(theta));
            const PixelCoord px = pixelOf(cam, p);
            ext = glm::max(ext, glm::abs(px - cam.principal()));
        }
    }
    return ext;
}

TEST(Camera, DefaultFramingCentresTheBoxAndItsSphereFillsAbout80Percent) {
    const glm::dvec3 lo(-3, 10, 2), hi(5, 14, 20);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    for (const auto& [w, h] : {std::pair(400, 400), std::pair(200, 400), std::pair(640, 360), std::pair(16, 16)}) {
        CameraSpec spec;
        spec.width = w;
        spec.height = h;
        const Camera cam = makeCamera(spec, lo, hi);
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        EXPECT_EQ(cam.lookAt(), centre);
        const PixelCoord c = pixelOf(cam, centre);
        EXPECT_NEAR(c.x, 0.5 * w, 1e-9);
        EXPECT_NEAR(c.y, 0.5 * h, 1e-9);
        EXPECT_NEAR(glm::length(glm::normalize(cam.eye() - centre) - defaultViewDirection()), 0.0, 1e-12);
        for (int k = 0; k < 8; ++k) {  // every corner inside the frame
            const glm::dvec3 p(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
            ASSERT_GT(cam.toView(p).z, 0.0);
            const PixelCoord px = pixelOf(cam, p);
            EXPECT_GT(px.x, 0.0);
            EXPECT_LT(px.x, double(w));
            EXPECT_GT(px.y, 0.0);
            EXPECT_LT(px.y, double(h));
        }
        // The sphere's silhouette spans about 80% of the smaller side (exactly
        // tan(0.8·half)/tan(half) of it: 0.79 for half = 15°), and fits the larger one.
        const glm::dvec2 ext = sphereExtent(cam, centre, radius);
        const double fill = 2.0 * std::max(ext.x / w, ext.y / h);
        EXPECT_GT(fill, 0.76);
        EXPECT_LT(fill, 0.82);
        EXPECT_LT(2.0 * ext.x, 0.82 * w);
        EXPECT_LT(2.0 * ext.y, 0.82 * h);
    }
}

TEST(Camera, DistanceScalesTheEyeDistance) {
    const glm::dvec3 lo(0, 0, 0), hi(99, 99, 99), centre(49.5);
    CameraSpec spec;
    const double d1 = glm::length(makeCamera(spec, lo, hi).eye() - centre);
    for (const double k : {8.0, 2.0, 0.35, 0.01}) {
        spec.distance = k;
        const Camera cam = makeCamera(spec, lo, hi);
        EXPECT_NEAR(glm::length(cam.eye() - centre), k * d1, 1e-9 * d1) << k;
        EXPECT_NEAR(glm::length(glm::normalize(cam.eye() - centre) - defaultViewDirection()), 0.0, 1e-12);
        EXPECT_EQ(cam.lookAt(), centre);
    }
    // Farther: the box looks proportionally smaller (small-angle).
    spec.distance = 8.0;
    const Camera far = makeCamera(spec, lo, hi);
    spec.distance = 16.0;
    const Camera farther = makeCamera(spec, lo, hi);
    const double a = glm::length(pixelOf(far, hi) - far.principal());
    const double b = glm::length(pixelOf(farther, hi) - farther.principal());
    EXPECT_NEAR(a / b, 2.0, 0.01);
}

// --view-dir and --up steer the framing: the eye lies along the direction at the same
// distance, the box stays centred, and the up vector is the image's up.
TEST(Camera, ViewDirAndUpSteerTheFraming) {
    const glm::dvec3 lo(0, 0, 0), hi(99, 49, 29), centre = 0.5 * (lo + hi);
    CameraSpec spec;
    const double d1 = glm::length(makeCamera(spec, lo, hi).eye() - centre);
    spec.hasViewDir = true;
    spec.viewDir = {0.0, 0.0, 5.0};  // any length
    spec.up = {0.0, 1.0, 0.0};
    const Camera top = makeCamera(spec, lo, hi);
    EXPECT_NEAR(glm::length(top.eye() - (centre + glm::dvec3(0.0, 0.0, d1))), 0.0, 1e-9 * d1);
    // Looking down −z with +y up: a point above the centre in y lands above the image centre.
    const PixelCoord above = top.project(top.toView(centre + glm::dvec3(0.0, 10.0, 0.0)));
    EXPECT_LT(above.y, top.principal().y - 1.0);
    EXPECT_NEAR(above.x, top.principal().x, 1e-9);
    spec.viewDir = {0.0, 0.0, 0.0};
    EXPECT_THROW(makeCamera(spec, lo, hi), Error);
    spec.viewDir = {0.0, 3.0, 0.0};  // parallel to up
    try {
        makeCamera(spec, lo, hi);
        ADD_FAILURE() << "up parallel to the view direction was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--up"), std::string::npos) << e.what();
    }
}

TEST(Camera, InvalidCamerasNameTheFlag) {
    const glm::dvec3 e(1, 2, 3), at(0, 0, 0), z(0, 0, 1);
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(has(errorOf([&] { Camera(e, e, z, 30, 8, 8); }), "--eye: equals --look-at")) << "eye == look-at";
    EXPECT_TRUE(has(errorOf([&] { Camera({0, 0, 5}, at, z, 30, 8, 8); }), "--up: parallel"));
    EXPECT_TRUE(has(errorOf([&] { Camera({0, 0, 5}, at, {0, 0, -2}, 30, 8, 8); }), "--up: parallel"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, at, {0, 0, 0}, 30, 8, 8); }), "--up"));
    for (const double fov : {0.0, -5.0, 170.0, 180.0, 1000.0, nan, inf})
        EXPECT_TRUE(has(errorOf([&] { Camera(e, at, z, fov, 8, 8); }), "--fov")) << fov;
    EXPECT_NO_THROW(Camera(e, at, z, 169.9, 8, 8));
    EXPECT_NO_THROW(Camera(e, at, z, 0.01, 8, 8));
    EXPECT_TRUE(has(errorOf([&] { Camera({nan, 0, 0}, at, z, 30, 8, 8); }), "--eye"));
    EXPECT_TRUE(has(errorOf([&] { Camera({inf, 0, 0}, at, z, 30, 8, 8); }), "--eye"));
    EXPECT_TRUE(has(errorOf([&] { Camera({1e300, 0, 0}, at, z, 30, 8, 8); }), "--eye: coordinates"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, {0, nan, 0}, z, 30, 8, 8); }), "--look-at"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, at, {0, 0, -inf}, 30, 8, 8); }), "--up"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, at, {1e300, 0, 0}, 30, 8, 8); }), "--up: coordinates"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, at, z, 30, 0, 8); }), "--size"));
    EXPECT_TRUE(has(errorOf([&] { Camera(e, at, z, 30, 8, -1); }), "--size"));

    CameraSpec spec;  // framing path
    for (const double d : {0.0, -1.0, nan, inf}) {
        spec.distance = d;
        EXPECT_TRUE(has(errorOf([&] { makeCamera(spec, at, e); }), "--distance")) << d;
    }
    spec.distance = 1.0;
    spec.fovDeg = 180.0;
    EXPECT_TRUE(has(errorOf([&] { makeCamera(spec, at, e); }), "--fov"));
    spec.fovDeg = nan;
    EXPECT_TRUE(has(errorOf([&] { makeCamera(spec, at, e); }), "--fov"));
}

TEST(Camera, DefaultFramingOfARotatedTranslatedHalfVoxelGrid) {
    initOpenVdb();
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    auto acc = g->getAccessor();
    for (int i = 0; i < 10; ++i) acc.setValueOn(openvdb::Coord(i, 2 * i, -i), 0.5f);
    auto xform = openvdb::math::Transform::createLinearTransform(0.5);
    xform->postRotate(0.6, openvdb::math::Y_AXIS);
    xform->postTranslate(openvdb::Vec3d(10, -20, 30));
    g->setTransform(xform);
    const Volume v = makeVolume(g);
    RenderSettings s;
    s.camera.width = 96;
    s.camera.height = 64;
    const Camera cam = cameraFor(v, s);
    // Every corner of every active voxel (index ± 0.5, mapped by OpenVDB's own transform) is in frame.
    double minX = 1e9, maxX = -1e9;
    for (int i = 0; i < 10; ++i)
        for (int k = 0; k < 8; ++k) {
            const openvdb::Vec3d ip(i + (k & 1 ? 0.5 : -0.5), 2 * i + (k & 2 ? 0.5 : -0.5), -i + (k & 4 ? 0.5 : -0.5));
            const openvdb::Vec3d w = xform->indexToWorld(ip);
            const PixelCoord px = pixelOf(cam, {w.x(), w.y(), w.z()});
            EXPECT_GT(px.x, 0.0);
            EXPECT_LT(px.x, 96.0);
            EXPECT_GT(px.y, 0.0);
            EXPECT_LT(px.y, 64.0);
            minX = std::min(minX, px.x);
            maxX = std::max(maxX, px.x);
        }
    EXPECT_GT(maxX - minX, 10.0);  // and it is not a speck
    // The look-at point is the centre of the world box of the voxels, which includes the translation.
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    EXPECT_NEAR(glm::length(cam.lookAt() - 0.5 * (lo + hi)), 0.0, 1e-12);
    const openvdb::Vec3d mid = xform->indexToWorld(openvdb::Vec3d(4.5, 9, -4.5));
    EXPECT_NEAR(glm::length(cam.lookAt() - glm::dvec3(mid.x(), mid.y(), mid.z())), 0.0, 1e-9);
}

}  // namespace
}  // namespace vdbsplat
