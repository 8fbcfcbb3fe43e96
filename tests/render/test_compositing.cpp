// tests/render/test_compositing.cpp — --compositing slabs end to end (docs/compositing.md):
// the same optical depth as the kernel order, closer to the reference where the colour steps in
// depth, and the same image for any thread count and any window size.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>

#include "metrics/metrics.h"
#include "render/render.h"
#include "scenes.h"
#include "volume/generate.h"

namespace vdbsplat {
namespace {

using test::boxVolume;
using test::settingsFor;
using test::constantTf;
using test::marschnerLobb;
using test::renderWith;

RenderSettings withOrder(RenderSettings s, CompositingOrder order) {
    s.compositing = order;
    return s;
}

RenderSettings lookingAt(RenderMode mode, glm::dvec3 eye, glm::dvec3 lookAt, int size) {
    RenderSettings s = settingsFor(mode, 1.0, size);
    s.camera.hasEye = true;
    s.camera.eye = eye;
    s.camera.lookAt = lookAt;
    s.camera.up = {0.0, 1.0, 0.0};
    return s;
}

/// Per pixel, the optical depth −ln T the image holds (T = 1 − alpha).
double opticalDepth(const glm::vec4& p) { return -std::log(std::max(1.0 - double(p.w), 1e-30)); }

// The energy rule across slabs: a lone voxel deposits, pixel by pixel, the optical depth it
// deposits in the kernel order (its fractions sum to 1): as a splat (close), as a point (far),
// for a stretched (ellipsoid) voxel, and for an aggregate of 2³ voxels (level of detail), in
// slabs of one voxel and of half a voxel.
TEST(SlabCompositing, LoneKernelDepositsTheOpticalDepthOfTheKernelOrder) {
    const TransferFunction tf = constantTf(0.3f, glm::vec3(0.8f, 0.6f, 0.4f));
    initOpenVdb();
    auto stretchedGrid = openvdb::FloatGrid::create(0.f);
    stretchedGrid->setName("density");
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(1.0);
    xf->preScale(openvdb::Vec3d(1.0, 1.0, 2.5));
    xf->preRotate(0.4, openvdb::math::X_AXIS);
    stretchedGrid->setTransform(xf);
    stretchedGrid->tree().setValue(openvdb::Coord(5, 5, 5), 1.f);
    const Volume stretched = makeVolume(stretchedGrid, "stretched");
    struct Case {
        const char* name;
        Volume volume;
        double distance;
        double lod;
    };
    const Case cases[] = {{"splat", boxVolume({5, 5, 5}, {5, 5, 5}), 0.4, 0.0},
                          {"point", boxVolume({5, 5, 5}, {5, 5, 5}), 40.0, 0.0},
                          {"ellipsoid", stretched, 0.5, 0.0},
                          {"aggregate", boxVolume({0, 0, 0}, {1, 1, 1}), 60.0, 8.0}};
    for (const Case& c : cases)
        for (const double thickness : {1.0, 0.5}) {
            RenderSettings s = settingsFor(RenderMode::Hybrid, c.distance, 64);
            s.lodPx = c.lod;
            RenderStats kernelStats, slabStats;
            const Image kernels = renderWith(c.volume, tf, s, &kernelStats);
            s.compositing = CompositingOrder::Slabs;
            s.slabThickness = thickness;
            const Image slabs = renderWith(c.volume, tf, s, &slabStats);
            EXPECT_EQ(kernelStats.points, slabStats.points) << c.name;
            EXPECT_EQ(kernelStats.splats, slabStats.splats) << c.name;
            if (std::string(c.name) == "aggregate") {
                EXPECT_GT(slabStats.lodAggregates, 0u);
            }
            double totalK = 0.0, totalS = 0.0;
            for (size_t i = 0; i < kernels.pixels.size(); ++i) {
                const double k = opticalDepth(kernels.pixels[i]), q = opticalDepth(slabs.pixels[i]);
                ASSERT_NEAR(q, k, 2e-6 + 2e-5 * k) << c.name << " pixel " << i;
                totalK += k, totalS += q;
                // one colour: the same premultiplied colour
                ASSERT_NEAR(slabs.pixels[i].x, kernels.pixels[i].x, 2e-6) << c.name << " pixel " << i;
            }
            EXPECT_GT(totalK, 0.0) << c.name;
            EXPECT_NEAR(totalS, totalK, 1e-5 * totalK) << c.name << " thickness " << thickness;
        }
}

// The 1-D case the slab order is for (scripts/sheet-order-1d.py): a uniform slab of voxels seen
// face on, shaded, so its first layer of voxels is lit and the ones behind it are not; along every
// ray the colour steps from one voxel to the next, and the kernels overlap in depth. The kernel
// order composites each splat whole at its centre; the reference integrates the sum. Measured
// (64², 16 rays): kernels 47.2 dB, slabs (half a voxel) 69.6 dB, slabs of one voxel 56.1 dB. The
// floor separates them: the kernel order fails it.
TEST(SlabCompositing, CloserToTheReferenceWhereTheColourStepsInDepth) {
    const TransferFunction tf = constantTf(0.5f, glm::vec3(0.5f));
    const Volume slab = boxVolume({0, 0, 0}, {31, 31, 9});
    RenderSettings s = lookingAt(RenderMode::Hybrid, {15.5, 15.5, -20.0}, {15.5, 15.5, 4.5}, 64);
    s.shading.mode = ShadingMode::Phong;
    s.shading.hasLight = true;  // grazing the face: its first layer is darker (D ≈ 0.5) than the rest (1)
    s.shading.light = {0.0, 1.0, -0.27};
    s.spp = 16;
    RenderSettings ref = s;
    ref.mode = RenderMode::Reference;
    const Image reference = renderWith(slab, tf, ref);
    const double kernels = compareImages(renderWith(slab, tf, withOrder(s, CompositingOrder::Kernels)), reference).psnr;
    const double slabs = compareImages(renderWith(slab, tf, withOrder(s, CompositingOrder::Slabs)), reference).psnr;
    RenderSettings one = withOrder(s, CompositingOrder::Slabs);
    one.slabThickness = 1.0;
    const double slabsOfOneVoxel = compareImages(renderWith(slab, tf, one), reference).psnr;
    std::printf("  lit face, 10 voxels deep, against the reference: kernels %.2f dB, slabs %.2f dB "
                "(slabs of one voxel %.2f dB)\n", kernels, slabs, slabsOfOneVoxel);
    constexpr double kFloor = 52.0;
    EXPECT_LT(kernels, kFloor);
    EXPECT_GT(slabsOfOneVoxel, kFloor);
    EXPECT_GT(slabs, kFloor + 12.0);
}

// Every primitive kind, both filter orders, sub-pixels, the level of detail (far) and narrow
// windows (a slab's deposits come from primitives of three windows): bit for bit the same with
// 1 and 2 threads, and the same whatever the window size.
TEST(SlabCompositing, ImagesDoNotDependOnThreadCountOrWindowSize) {
    const TransferFunction tf = TransferFunction::preset("grey");
    struct Case {
        double distance;
        FilterOrder order;
        int subpixels;
    };
    for (const Case c : {Case{1.0, FilterOrder::Postfilter, 1}, Case{0.35, FilterOrder::Postfilter, 1},
                         Case{1.0, FilterOrder::Prefilter, 1}, Case{1.0, FilterOrder::Postfilter, 2},
                         Case{8.0, FilterOrder::Postfilter, 1}}) {
        RenderSettings s = withOrder(settingsFor(RenderMode::Hybrid, c.distance), CompositingOrder::Slabs);
        s.filterOrder = c.order, s.subpixels = c.subpixels;
        s.shading.mode = ShadingMode::Phong;
        // Narrow windows: by records, and a far view's are few (its 8³ cells: one a leaf).
        s.stream.minWindowVoxels = c.distance > 4.0 ? 16 : 256;
        s.stream.maxWindowVoxels = 2000;
        Image one, two, wide;
        RenderStats narrowStats, wideStats;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = renderWith(marschnerLobb(), tf, s, &narrowStats);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = renderWith(marschnerLobb(), tf, s);
            RenderSettings w = s;
            w.stream = StreamOptions{};
            wide = renderWith(marschnerLobb(), tf, w, &wideStats);
        }
        EXPECT_GT(narrowStats.windows, 2 * wideStats.windows) << c.distance;
        ASSERT_EQ(one.pixels.size(), two.pixels.size());
        for (size_t i = 0; i < one.pixels.size(); ++i) {
            ASSERT_EQ(one.pixels[i], two.pixels[i]) << c.distance << " pixel " << i;
            ASSERT_EQ(one.pixels[i], wide.pixels[i]) << c.distance << " windows, pixel " << i;
        }
    }
}

// Every forward mode draws through the slab order (the study modes' kernels included): bit for bit
// the same with 1 and 2 threads, and no further from the reference than the kernel order.
TEST(SlabCompositing, EveryForwardModeTakesIt) {
    const TransferFunction tf = TransferFunction::preset("grey");
    const Image reference = renderWith(marschnerLobb(), tf, settingsFor(RenderMode::Reference, 1.0));
    for (const RenderMode mode : {RenderMode::Hybrid, RenderMode::Point, RenderMode::Splat, RenderMode::Ewa,
                                  RenderMode::Swan, RenderMode::None}) {
        const RenderSettings s = settingsFor(mode, 1.0);
        const double kernels = compareImages(renderWith(marschnerLobb(), tf, s), reference).psnr;
        Image one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = renderWith(marschnerLobb(), tf, withOrder(s, CompositingOrder::Slabs));
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = renderWith(marschnerLobb(), tf, withOrder(s, CompositingOrder::Slabs));
        }
        EXPECT_EQ(one.pixels, two.pixels) << toString(mode);
        const double slabs = compareImages(one, reference).psnr;
        std::printf("  %-6s against the reference: kernels %.2f dB, slabs %.2f dB\n", toString(mode).c_str(), kernels, slabs);
        EXPECT_GT(slabs, kernels - 0.5) << toString(mode);
    }
}

// The scalar table path (--simd off) is the oracle of the vector loops in both orders: the
// splats, and the points' slabs (in the kernel order composited over the rectangle their points
// touched, compositeSlabVector's TileRect), near and far.
TEST(SlabCompositing, VectorLoopsMatchTheScalarPaths) {
    const TransferFunction tf = TransferFunction::preset("grey");
    for (const CompositingOrder order : {CompositingOrder::Kernels, CompositingOrder::Slabs})
    for (const double distance : {0.35, 1.0, 3.0, 8.0}) {
        RenderSettings s = withOrder(settingsFor(RenderMode::Hybrid, distance), order);
        const Image vector = renderWith(marschnerLobb(), tf, s);
        s.simd = false;
        const Image scalar = renderWith(marschnerLobb(), tf, s);
        for (size_t i = 0; i < vector.pixels.size(); ++i)
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(vector.pixels[i][c], scalar.pixels[i][c], 2e-5) << distance << " pixel " << i;
    }
}

// Early termination and hidden-block culling keep working: a dense box seen face on hides its
// back, whose blocks are never streamed, and the image is the kernel order's (one colour).
TEST(SlabCompositing, OpaqueFrontHidesTheBack) {
    const TransferFunction tf = constantTf(4.f);
    const Volume box = boxVolume({0, 0, 0}, {31, 31, 63});
    RenderSettings s = lookingAt(RenderMode::Hybrid, {15.5, 15.5, -30.0}, {15.5, 15.5, 30.0}, 48);
    RenderStats kernelStats, slabStats;
    const Image kernels = renderWith(box, tf, s, &kernelStats);
    const Image slabs = renderWith(box, tf, withOrder(s, CompositingOrder::Slabs), &slabStats);
    EXPECT_GT(slabStats.culledOccluded, 0u);
    EXPECT_LT(slabStats.splats + slabStats.points, uint64_t(32 * 32 * 64) / 2);
    EXPECT_GT(compareImages(slabs, kernels).psnr, 60.0);
}

// Octant culling (StreamOptions::octantCulling) changes what is streamed, never the image: a box
// seen from off every axis, opaque within a few voxels, where the leaves along the edges of what
// is already opaque are partly hidden. Bit-identical images, kernel and slab order, and more
// voxels counted occluded (never classified), fewer dropped after projection. Shaded, the leaves
// take the voxel-by-voxel extraction, which honours the octants too.
TEST(SlabCompositing, OctantCullingKeepsTheImage) {
    const TransferFunction tf = constantTf(1.5f);
    const Volume box = boxVolume({0, 0, 0}, {47, 39, 55});
    for (const ShadingMode shading : {ShadingMode::Off, ShadingMode::Phong})
    for (const CompositingOrder order : {CompositingOrder::Kernels, CompositingOrder::Slabs}) {
        RenderSettings s = withOrder(lookingAt(RenderMode::Hybrid, {-40.0, 70.0, -60.0}, {24.0, 20.0, 28.0}, 96), order);
        s.shading.mode = shading;
        RenderStats on, off;
        const Image culled = renderWith(box, tf, s, &on);
        Image oneThread;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            oneThread = renderWith(box, tf, s);
        }
        EXPECT_TRUE(culled.pixels == oneThread.pixels) << "octant culling made the image depend on the thread count";
        s.stream.octantCulling = false;
        const Image whole = renderWith(box, tf, s, &off);
        ASSERT_EQ(culled.pixels.size(), whole.pixels.size());
        EXPECT_TRUE(culled.pixels == whole.pixels) << "octant culling changed the image";
        EXPECT_GT(on.culledOccluded, off.culledOccluded + 1000);
        EXPECT_LT(on.culledHidden, off.culledHidden);
        // (Not the same counts otherwise: fewer voxels released make later windows deeper, so the
        // primitives' own tests come at other moments.)
    }
}

}  // namespace
}  // namespace vdbsplat
