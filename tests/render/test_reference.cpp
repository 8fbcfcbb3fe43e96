// tests/render/test_reference.cpp — the reference renderer against closed forms (DESIGN §1).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "footprint/kernel.h"
#include "render/reference.h"
#include "render/render.h"
#include "scenes.h"

namespace vdbsplat {
namespace {

using test::boxVolume;
using test::constantTable;

// A uniform slab of N voxel layers transmits exp(−σN): the kernels are a partition of unity.
TEST(Reference, UniformSlabTransmittanceIsExpMinusSigmaL) {
    const int layers = 12;
    const Volume slab = boxVolume({-30, -30, 0}, {30, 30, layers - 1});
    for (const float sigma : {0.02f, 0.1f, 0.3f}) {
        const ClassificationTable table = constantTable(sigma, glm::vec3(0.25f, 0.5f, 1.0f));
        RayIntegrator integrator(slab, table);
        for (const glm::dvec3 dir : {glm::dvec3(0, 0, 1), glm::normalize(glm::dvec3(0.2, -0.1, 1.0))}) {
            const glm::dvec3 origin = glm::dvec3(0.3, -0.2, -20.0);
            const double pathLength = layers / dir.z;  // voxels crossed along the oblique ray
            const double expectedAlpha = 1.0 - std::exp(-sigma * pathLength);
            const glm::dvec4 c = integrator.integrate(origin, dir);
            EXPECT_NEAR(c.w, expectedAlpha, 2e-4 + 1e-3 * expectedAlpha) << "sigma " << sigma;
            // Constant colour: C = c · (1 − T).
            EXPECT_NEAR(c.x, 0.25 * c.w, 1e-6);
            EXPECT_NEAR(c.z, 1.0 * c.w, 1e-6);
            EXPECT_NEAR(integrator.opticalDepth(origin, dir), sigma * pathLength, 2e-3 * sigma * pathLength);
        }
    }
}

// One isolated kernel deposits σ·F(ρ) along a ray at distance ρ from its centre,
// in any linear transform (voxel size, translation, rotation).
TEST(Reference, IsolatedKernelDepositsItsLineIntegral) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    auto xf = openvdb::math::Transform::createLinearTransform(0.5);
    xf->postRotate(0.4, openvdb::math::Z_AXIS);
    xf->postRotate(-0.3, openvdb::math::X_AXIS);
    xf->postTranslate(openvdb::Vec3d(10.0, -3.0, 2.0));
    grid->setTransform(xf);
    grid->tree().setValueOn(openvdb::Coord(4, 5, 6), 1.f);
    const Volume volume = makeVolume(grid, "single");
    const float sigma = 0.7f;
    const ClassificationTable table = constantTable(sigma);
    RayIntegrator integrator(volume, table);
    const glm::dvec3 centre(volume.indexToWorld * glm::dvec4(4, 5, 6, 1));
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.3, 1.0, -0.2));
    const glm::dvec3 side = glm::normalize(glm::cross(dir, glm::dvec3(0, 0, 1)));
    for (const double rho : {0.0, 0.5, 1.0, 1.5, 1.95, 2.05}) {
        const glm::dvec3 origin = centre + side * (rho * volume.voxelSize) - dir * 10.0;
        const double expected = sigma * Kernel::footprint(rho);
        EXPECT_NEAR(integrator.opticalDepth(origin, dir), expected, 1e-9) << "rho " << rho;
        const glm::dvec4 c = integrator.integrate(origin, dir);
        EXPECT_NEAR(c.w, 1.0 - std::exp(-expected), 1e-5) << "rho " << rho;
    }
    // A ray starting at the centre sees half the kernel; one pointing away sees it only behind the eye.
    EXPECT_NEAR(integrator.opticalDepth(centre, dir), 0.5 * sigma * Kernel::footprint(0.0), 1e-5);
    EXPECT_NEAR(integrator.opticalDepth(centre + dir * 3.0, dir), 0.0, 1e-12);
}

// Skipping empty space changes the work, never a ray: with regions that cover the whole
// bounding box (the full walk of every slice, as before issue 12) every ray of a sparse grid
// of far-apart clusters integrates to bit-identical colour, alpha and optical depth.
TEST(Reference, EmptySpaceSkippingLeavesEveryRayBitIdentical) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    uint32_t h = 12345;
    const openvdb::Coord centres[] = {{0, 0, 0}, {300, 40, -20}, {-150, 260, 90}, {140, 130, 40}};
    for (const openvdb::Coord& c : centres)
        for (int i = 0; i < 400; ++i) {
            h = h * 1664525u + 1013904223u;
            grid->tree().setValueOn(c + openvdb::Coord(int(h >> 8) % 9, int(h >> 16) % 9, int(h >> 24) % 9),
                                    float((h >> 4) % 100) / 100.f);
        }
    const Volume volume = makeVolume(grid, "clusters");
    auto cover = openvdb::FloatGrid::create(0.f);
    cover->tree().fill(volume.indexBox, 1.f, true);
    const ActiveRegions everything(cover->tree());
    const ClassificationTable table = test::rampTable(0.6f);
    RayIntegrator skipping(volume, table), full(volume, table, &everything);
    const glm::dvec3 eye(-400.0, -300.0, 250.0);
    int hits = 0;
    for (int i = 0; i < 400; ++i) {
        h = h * 1664525u + 1013904223u;
        const openvdb::Coord& c = centres[i % 4];
        const glm::dvec3 target(c.x() + 4.0 + (h % 1000) / 100.0 - 5.0, c.y() + 4.0 + ((h >> 10) % 1000) / 100.0 - 5.0,
                                c.z() + 4.0);
        const glm::dvec3 dir = target - eye;
        const glm::dvec4 a = skipping.integrate(eye, dir), b = full.integrate(eye, dir);
        EXPECT_EQ(a, b) << "ray " << i;
        EXPECT_EQ(skipping.opticalDepth(eye, dir), full.opticalDepth(eye, dir)) << "ray " << i;
        hits += a.w > 0.0;
    }
    EXPECT_GT(hits, 200);  // the rays do cross the clusters
}

RenderSettings smallSettings(int width, int height) {
    RenderSettings s;
    s.mode = RenderMode::Reference;
    s.camera.width = width;
    s.camera.height = height;
    s.spp = 16;
    return s;
}

// A scene symmetric under x → −x, seen from the symmetry plane, renders a mirror-symmetric image.
TEST(Reference, SymmetricSceneRendersSymmetricImage) {
    const Volume box = boxVolume({-8, -5, -6}, {8, 5, 6});
    RenderSettings s = smallSettings(48, 40);
    s.camera.hasEye = true;
    s.camera.eye = {0.0, -40.0, 15.0};
    s.camera.lookAt = {0.0, 0.0, 0.0};
    s.transferFunction = "grey";
    RenderStats stats;
    const Image image = render(box, TransferFunction::preset("grey"), s, stats);
    double maxDiff = 0.0, maxValue = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const glm::vec4 a = image.at(x, y), b = image.at(image.width - 1 - x, y);
            maxDiff = std::max<double>(maxDiff, glm::length(a - b));
            maxValue = std::max<double>(maxValue, a.w);
        }
    EXPECT_GT(maxValue, 0.3);  // something was drawn
    EXPECT_LT(maxDiff, 0.02);  // only the jitter pattern breaks the symmetry
}

TEST(Reference, ImageDoesNotDependOnThreadCount) {
    const Volume box = boxVolume({-8, -5, -6}, {8, 5, 6});
    RenderSettings s = smallSettings(40, 32);
    const TransferFunction tf = TransferFunction::preset("grey");
    Image one, two;
    RenderStats stats;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = render(box, tf, s, stats);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = render(box, tf, s, stats);
    }
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    for (size_t i = 0; i < one.pixels.size(); ++i) ASSERT_EQ(one.pixels[i], two.pixels[i]) << "pixel " << i;
}

}  // namespace
}  // namespace vdbsplat
