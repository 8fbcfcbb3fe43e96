// tests/render/test_emission.cpp — emission grids end to end (docs/emission.md): the energy of
// one emitting voxel against the point energy rule (DESIGN §4) in every mode and in the
// reference, emission without absorption, the hybrid against the reference on the generated
// explosion with temperature emission, and the image's independence of the thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstdio>

#include "metrics/metrics.h"
#include "pointfilter/point_filter.h"
#include "render/render.h"
#include "scenes.h"
#include "volume/emission.h"
#include "volume/generate.h"

namespace vdbsplat {
namespace {

using test::constantTf;

constexpr int kSize = 96;

/// One density voxel of value @p value at the origin, voxel size @p h.
Volume oneVoxel(float value, double h = 1.0) { return test::boxVolume(openvdb::Coord(0), openvdb::Coord(0), value, h); }

/// An emission grid of value 1 on the index box [lo, hi], same transform as @p like.
Volume emissionBox(const Volume& like, openvdb::Coord lo, openvdb::Coord hi) {
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("temperature");
    grid->setTransform(std::make_shared<openvdb::math::Transform>(like.map->copy()));
    grid->denseFill(openvdb::CoordBBox(lo, hi), 1.f, true);
    grid->tree().voxelizeActiveTiles();
    return makeVolume(grid, "test-emission");
}

/// The emission settings of a constant map: ε = scale · σ · c = @p epsilon (per voxel length).
EmissionSettings constantEmission(const std::string& file) {
    EmissionSettings e;
    e.grid = "temperature";
    e.map = file;
    e.scale = 1.0;
    return e;
}

/// Looking at the world origin from @p distance along an oblique direction (the whole kernel on screen).
RenderSettings view(RenderMode mode, double distance) {
    RenderSettings s;
    s.mode = mode;
    s.camera.width = s.camera.height = kSize;
    s.camera.hasEye = true;
    s.camera.eye = distance * glm::normalize(glm::dvec3(0.3, -0.2, 1.0));
    s.camera.lookAt = glm::dvec3(0.0);
    s.camera.up = {0.0, 1.0, 0.0};
    s.spp = 16;
    return s;
}

glm::dvec3 radianceSum(const Image& image) {
    glm::dvec3 sum(0.0);
    for (const glm::vec4& p : image.pixels) sum += glm::dvec3(p);
    return sum;
}

/// Writes a constant transfer function file (σ = 1 per voxel, colour @p rgb): as an emission
/// map it gives ε = @p rgb per voxel length.
std::string constantMapFile(glm::vec3 rgb) {
    const std::string path = testing::TempDir() + "vdbsplat_emission_map.json";
    FILE* f = std::fopen(path.c_str(), "w");
    std::fprintf(f, R"({"name": "const", "color": [[0, %g, %g, %g], [1, %g, %g, %g]], "extinction": [[0, 1], [1, 1]]})",
                 rgb.x, rgb.y, rgb.z, rgb.x, rgb.y, rgb.z);
    std::fclose(f);
    return path;
}

// A single voxel that emits and does not absorb (its density classifies to σ = 0): the image's
// total radiance is its emission ε times the point energy rule's screen integral,
// pointDepositTotal(ε/h, h, f, c) — in point mode (the rule itself), splat mode (the splat's
// deposits sum to the point's total) and the reference (the ray integral of the same field).
TEST(Emission, SingleEmittingVoxelDepositsThePointTotal) {
    const glm::vec3 epsilon(0.8f, 0.4f, 0.1f);
    const std::string map = constantMapFile(epsilon);
    for (double h : {1.0, 0.5}) {
        Volume v = oneVoxel(0.5f, h);
        attachEmission(v, emissionBox(v, openvdb::Coord(0), openvdb::Coord(0)));
        const TransferFunction clear = constantTf(0.f, glm::vec3(1.f));
        // Kernel radius 2h: about 2 px at 180h, 20 px at 18h (f ≈ 179 px). Closer, the small-kernel
        // rule itself is off (2.5 % at 8h, where the kernel subtends ±14°), for every mode alike.
        for (const auto& [mode, distance, tolerance] : {std::tuple{RenderMode::Point, 180.0, 2e-3},
                                                        std::tuple{RenderMode::Splat, 18.0, 1e-2},
                                                        std::tuple{RenderMode::Hybrid, 18.0, 1e-2},
                                                        std::tuple{RenderMode::Reference, 18.0, 1e-2}}) {
            RenderSettings s = view(mode, distance * h);
            s.emission = constantEmission(map);
            RenderStats stats;
            const Image image = render(v, clear, s, stats);
            const Camera camera = cameraFor(v, s);
            const glm::dvec3 c = camera.toView(glm::dvec3(v.indexToWorld * glm::dvec4(0.0, 0.0, 0.0, 1.0)));
            const double unit = pointDepositTotal(1.0 / h, h, camera.focal(), c);  // ε = 1 per voxel length
            const glm::dvec3 sum = radianceSum(image);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(sum[k] / (unit * epsilon[k]), 1.0, tolerance)
                    << toString(mode) << " distance " << distance << " h " << h << " channel " << k;
            // No absorption: alpha is the negligible kEmissionOnlySigma's.
            double alpha = 0.0;
            for (const glm::vec4& p : image.pixels) alpha += p.w;
            EXPECT_LT(alpha, 1e-5 * unit) << toString(mode);
        }
    }
}

// Emission adds to the density's own emission: σc + ε, with the density's extinction kept.
TEST(Emission, AddsToTheDensityEmissionAndKeepsItsExtinction) {
    const Classified dense{glm::vec3(0.5f, 0.5f, 0.5f), 2.f};
    const Classified lit = applyEmission(dense, glm::vec3(1.f, 0.f, 0.f));
    EXPECT_FLOAT_EQ(lit.sigma, 2.f);
    EXPECT_FLOAT_EQ(lit.sigma * lit.color.x, 2.f * 0.5f + 1.f);
    EXPECT_FLOAT_EQ(lit.sigma * lit.color.y, 2.f * 0.5f);
    const Classified clear = applyEmission(Classified{glm::vec3(0.f), 0.f}, glm::vec3(0.f, 2.f, 0.f));
    EXPECT_EQ(clear.sigma, kEmissionOnlySigma);
    EXPECT_FLOAT_EQ(clear.sigma * clear.color.y, 2.f);
    const Classified none = applyEmission(dense, glm::vec3(0.f));
    EXPECT_EQ(none.sigma, dense.sigma);
    EXPECT_EQ(none.color, dense.color);
}

const std::vector<openvdb::FloatGrid::Ptr>& explosion() {
    static const std::vector<openvdb::FloatGrid::Ptr> grids = makeExplosion(32, 1);
    return grids;
}

Volume explosionVolume() {
    Volume v = makeVolume(explosion()[0]->deepCopy(), "explosion");
    attachEmission(v, makeVolume(explosion()[1], "explosion"));
    return v;
}

RenderSettings explosionView(RenderMode mode, double distance) {
    RenderSettings s = test::settingsFor(mode, distance, kSize);
    s.emission.grid = "temperature";
    s.emission.scale = 0.6;
    return s;
}

// The issue's test for every term: hybrid against the reference, here with temperature
// emission on the generated explosion, at the three standard views. Floors set from the
// measured values (printed; 51.5, 68.3, 62.7 dB) with a margin of 3.5–4.3 dB.
/// Dark smoke (docs/smoke.json): the emission is what shows.
TransferFunction smokeTf() {
    return TransferFunction::fromPoints("smoke", {{0.f, glm::vec3(0.02f)}, {1.f, glm::vec3(0.12f, 0.11f, 0.10f)}},
                                        {{0.f, 0.f}, {0.3f, 0.02f}, {1.f, 0.12f}});
}

TEST(Emission, HybridMatchesTheReferenceOnTheExplosion) {
    const Volume v = explosionVolume();
    const TransferFunction tf = smokeTf();
    struct Case { double distance, floor; };
    for (const Case c : {Case{8.0, 48.0}, Case{1.0, 64.0}, Case{0.35, 59.0}}) {
        RenderStats stats;
        const Image ref = render(v, tf, explosionView(RenderMode::Reference, c.distance), stats);
        const Image hybrid = render(v, tf, explosionView(RenderMode::Hybrid, c.distance), stats);
        RenderSettings off = explosionView(RenderMode::Hybrid, c.distance);
        off.emission = {};
        const Image dark = render(v, tf, off, stats);
        const double psnr = compareImages(hybrid, ref).psnr;
        std::printf("  explosion hybrid distance %-5g PSNR %6.2f dB (emission adds %.3g of radiance)\n", c.distance, psnr,
                    radianceSum(hybrid).x - radianceSum(dark).x);
        EXPECT_GE(psnr, c.floor) << "distance " << c.distance;
        EXPECT_GT(radianceSum(hybrid).x, 3.0 * radianceSum(dark).x) << "emission must show";
    }
}

// A scale of 0 changes nothing: the emission path adds exactly ε.
TEST(Emission, ZeroScaleGivesTheImageWithoutEmission) {
    const Volume v = explosionVolume();
    const TransferFunction tf = TransferFunction::preset("grey");
    RenderSettings s = explosionView(RenderMode::Hybrid, 1.0);
    s.emission.scale = 0.0;
    RenderStats stats;
    const Image a = render(v, tf, s, stats);
    s.emission = {};
    const Image b = render(v, tf, s, stats);
    EXPECT_EQ(a.pixels, b.pixels);
}

TEST(Emission, ImagesDoNotDependOnThreadCount) {
    const Volume v = explosionVolume();
    const TransferFunction tf = TransferFunction::preset("grey");
    for (RenderMode mode : {RenderMode::Hybrid, RenderMode::Reference}) {
        RenderSettings s = explosionView(mode, 0.35);
        s.camera.width = s.camera.height = 48;
        RenderStats stats;
        Image one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = render(v, tf, s, stats);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = render(v, tf, s, stats);
        }
        EXPECT_EQ(one.pixels, two.pixels) << toString(mode);
    }
}

// --compositing slabs with an emission grid: the emission is a colour per voxel like any other,
// so the slab order renders the explosion at least as close to the reference as the kernel order,
// and the same for 1 and 2 threads.
TEST(Emission, SlabOrderKeepsEmissionAndThreadInvariance) {
    const Volume v = explosionVolume();
    const TransferFunction tf = smokeTf();
    for (const double distance : {1.0, 0.35}) {
        RenderStats stats;
        RenderSettings s = explosionView(RenderMode::Hybrid, distance);
        s.camera.width = s.camera.height = 48;
        RenderSettings ref = s;
        ref.mode = RenderMode::Reference;
        const Image reference = render(v, tf, ref, stats);
        const double kernels = compareImages(render(v, tf, s, stats), reference).psnr;
        s.compositing = CompositingOrder::Slabs;
        Image one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = render(v, tf, s, stats);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = render(v, tf, s, stats);
        }
        EXPECT_EQ(one.pixels, two.pixels) << distance;
        const double slabs = compareImages(one, reference).psnr;
        std::printf("  explosion distance %-5g: kernels %.2f dB, slabs %.2f dB\n", distance, kernels, slabs);
        EXPECT_GT(slabs, kernels - 0.5) << distance;
    }
}

}  // namespace
}  // namespace vdbsplat
