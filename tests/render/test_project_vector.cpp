// tests/render/test_project_vector.cpp — the vector splat projection (render/project_vector.h)
// against projectVoxel, its scalar oracle: every lane it takes must give the very primitive
// projectVoxel gives (bit for bit), and it must take exactly the lanes whose kernel sphere
// makeSplat projects to an ellipse (on the image or culled off it), in every mode and footprint path it serves, near and far, on and off the
// axis, at the eye plane, behind the eye, off the image and non-finite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/tables.h"
#include "render/project.h"
#include "support/projection.h"
#include "support/targets.h"
#include "render/project_vector.h"

namespace vdbsplat {
namespace {

const Tables& tables() { return test::sharedTables(); }
Camera testCamera(int size) { return test::boxCamera(size); }

/// Voxel centres of every kind the projection meets (h = 0.1, kernel radius 0.2; f ≈ 119 px at 64 px).
std::vector<glm::vec3> testVoxels() {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<glm::vec3> v;
    for (int i = 0; i < 6000; ++i) {
        const float z = -1.f + 45.f * u(rng) * u(rng);  // many near: large, off-axis splats
        const float spread = 0.7f * std::max(std::abs(z), 0.3f);  // a little past the frustum's edges
        v.emplace_back((u(rng) - 0.5f) * spread, (u(rng) - 0.5f) * spread, z);
    }
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    for (const float z : {0.05f, 0.19f, 0.2f, 0.21f, 0.4f, 1.f, 30.f}) v.emplace_back(0.f, 0.f, z);  // on the axis
    for (const float z : {0.2f, 0.2000001f, 0.25f}) v.emplace_back(0.3f, 0.f, z);                  // at the eye plane
    v.emplace_back(0.f, 0.f, 0.f);
    v.emplace_back(0.f, 0.f, -5.f);
    v.emplace_back(nan, 0.f, 3.f);
    v.emplace_back(0.f, inf, 3.f);
    v.emplace_back(0.f, 0.f, inf);
    v.emplace_back(1e30f, 1e30f, 1e30f);
    return v;
}

struct Coverage {
    int splats = 0, exact = 0, offImage = 0, declined = 0;
};

void checkLanes(const ProjectionContext& ctx, const std::vector<glm::vec3>& voxels, Coverage& cov) {
    const std::optional<SplatLaneContext> lc = splatLaneContext(ctx);
    ASSERT_TRUE(lc.has_value());
    SplatLanes lanes;
    for (size_t begin = 0; begin < voxels.size(); begin += kSplatLanes) {
        const size_t n = std::min(kSplatLanes, voxels.size() - begin);
        for (size_t k = 0; k < n; ++k)
            lanes.x[k] = voxels[begin + k].x, lanes.y[k] = voxels[begin + k].y, lanes.z[k] = voxels[begin + k].z;
        projectSplatsVector(lanes, n, *lc);
        for (size_t k = 0; k < n; ++k) {
            const glm::vec3 c = voxels[begin + k];
            const Primitive q = projectVoxel(glm::dvec3(c), 0.7f, glm::vec3(0.2f, 0.5f, 0.9f), ctx);
            // makeSplat's ellipse: a splat (not a point in hybrid) whose sphere projects to an ellipse.
            const double spacingPx = c.z > 0.f ? ctx.voxelSize * ctx.camera.focal() / double(c.z) : INFINITY;
            const bool point = ctx.mode == RenderMode::Hybrid && spacingPx < ctx.threshold;
            const bool ellipse = !point && projectSphere(ctx.camera, glm::dvec3(c), Kernel::kRadius * ctx.voxelSize).isEllipse();
            const uint8_t status = lanes.status[k];
            ASSERT_EQ(status != SplatLanes::kScalar, ellipse) << "voxel " << c.x << ", " << c.y << ", " << c.z;
            if (!ellipse) {
                ++cov.declined;
                continue;
            }
            const bool exact = status & SplatLanes::kExactIndex;
            if (status & SplatLanes::kOffImage) {
                ++cov.offImage;
                ASSERT_EQ(q.kind, PrimitiveKind::Culled);
                ASSERT_TRUE(q.range.empty());
                ASSERT_EQ(q.hasExactMap, exact);
            } else {
                ++(exact ? cov.exact : cov.splats);
                ASSERT_EQ(q.kind, exact ? PrimitiveKind::SplatExactIndex : PrimitiveKind::Splat);
            }
            ASSERT_EQ(q.centre, glm::vec2(float(lanes.centreX[k]), float(lanes.centreY[k])));
            ASSERT_EQ(q.conic, glm::vec3(float(lanes.conicXX[k]), float(lanes.conicXY[k]), float(lanes.conicYY[k])));
            ASSERT_EQ(q.scale, float(0.7f * lanes.amplitude[k]));
            ASSERT_EQ(q.sin2Alpha, float(lanes.sinAlpha[k] * lanes.sinAlpha[k]));
            const PixelRange r = lanes.range(k);
            ASSERT_TRUE(r.x0 == q.range.x0 && r.y0 == q.range.y0 && r.x1 == q.range.x1 && r.y1 == q.range.y1);
            if (exact) {
                const ExactIndexMap m = lanes.exactMap(k);
                ASSERT_TRUE(m == q.exactMap);
            }
        }
    }
}

TEST(ProjectVector, LanesEqualTheScalarProjection) {
    const Camera camera = testCamera(64);
    const std::vector<glm::vec3> voxels = testVoxels();
    for (const RenderMode mode : {RenderMode::Hybrid, RenderMode::Splat})
        for (const FootprintPath footprint : {FootprintPath::Auto, FootprintPath::Table})
            for (const double prefilter : {kPrefilterVariance, 0.1, 0.0}) {
                ProjectionContext ctx{camera, tables(), 0.1, 0.1, mode, 1.0, footprint, false, prefilter};
                ctx.magnifiedPrefilterVariance = 0.5 * prefilter;  // the ramp between τ and 2τ (lowPass), in both paths
                SCOPED_TRACE(toString(mode) + " prefilter " + std::to_string(prefilter));
                Coverage cov;
                checkLanes(ctx, voxels, cov);
                // Both kinds, and every class the scalar path keeps, occur.
                if (footprint == FootprintPath::Auto) {  // near the axis the affine index, off it the exact one
                    EXPECT_GT(cov.splats, 5);
                    EXPECT_GT(cov.exact, 300);
                } else {
                    EXPECT_GT(cov.splats, 300);
                    EXPECT_EQ(cov.exact, 0);
                }
                EXPECT_GT(cov.offImage, 300);
                EXPECT_GT(cov.declined, 300);
            }
}

/// The points' lanes (projectPointsVector) against projectVoxel's makePoint and setUpPointFilter:
/// every lane taken as a point must be the scalar path's primitive bit for bit, and every
/// minified voxel makePoint keeps must be taken (culled points and the one-pixel fallback of an
/// empty filter sum are the scalar path's).
void checkPointLanes(const ProjectionContext& ctx, const std::vector<glm::vec3>& voxels, Coverage& cov) {
    const std::optional<SplatLaneContext> lc = splatLaneContext(ctx);  // none in point mode
    const std::optional<PointLaneContext> pc = pointLaneContext(ctx);
    ASSERT_TRUE(pc.has_value());
    ASSERT_EQ(lc.has_value(), ctx.mode == RenderMode::Hybrid);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    SplatLanes lanes;
    PointLanes points;
    for (size_t begin = 0; begin < voxels.size(); begin += kSplatLanes) {
        const size_t n = std::min(kSplatLanes, voxels.size() - begin);
        for (size_t k = 0; k < kSplatLanes; ++k) {
            const glm::vec3 c = k < n ? voxels[begin + k] : glm::vec3(0.f);
            lanes.x[k] = c.x, lanes.y[k] = c.y, lanes.z[k] = c.z;
            // σ: mostly ordinary, some 0 and some so small that the total underflows (both culled);
            // spread: a voxel's 0 or an aggregate's.
            const float r = u(rng);
            points.sigma[k] = k >= n ? 0.f : r < 0.05f ? 0.f : r < 0.1f ? 1e-44f : 0.05f + 3.f * u(rng);
            points.spread[k] = k >= n || u(rng) < 0.5f ? 0.f : 2.f * u(rng);
        }
        if (lc) projectSplatsVector(lanes, n, *lc);
        else std::fill(std::begin(lanes.status), std::end(lanes.status), SplatLanes::kScalar);
        projectPointsVector(lanes, points, n, *pc);
        for (size_t k = 0; k < n; ++k) {
            const glm::vec3 c = voxels[begin + k];
            const Primitive q = projectVoxel(glm::dvec3(c), points.sigma[k], glm::vec3(0.2f, 0.5f, 0.9f), ctx, points.spread[k]);
            const bool point = std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.z > 0.f &&
                               (ctx.mode == RenderMode::Point || ctx.voxelSize * ctx.camera.focal() / double(c.z) < ctx.threshold);
            const uint8_t status = points.status[k];
            SCOPED_TRACE("voxel " + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z));
            if (!point) {
                ASSERT_EQ(status, PointLanes::kScalar);
                ++cov.declined;
                continue;
            }
            ASSERT_EQ(lanes.status[k], SplatLanes::kScalar);  // the splat lanes left it
            if (q.kind == PrimitiveKind::Culled) {
                ASSERT_EQ(status, PointLanes::kScalar);
                ++cov.offImage;
                continue;
            }
            ASSERT_EQ(q.kind, PrimitiveKind::Point);
            if (status == PointLanes::kScalar) {  // only the one-pixel fallback
                ASSERT_EQ(q.pointRadius2, INFINITY);
                ++cov.exact;
                continue;
            }
            ASSERT_EQ(status, PointLanes::kPoint);
            ++cov.splats;
            ASSERT_EQ(q.centre, glm::vec2(points.centreX[k], points.centreY[k]));
            ASSERT_EQ(q.variance, points.variance[k]);
            ASSERT_EQ(q.total, points.total[k]);
            ASSERT_EQ(q.pointInvVariance, points.invVariance[k]);
            ASSERT_EQ(q.pointRadius2, points.radius2[k]);
            ASSERT_EQ(q.pointNorm, points.norm[k]);
            const PixelRange r = points.range(k, ctx.camera.width(), ctx.camera.height());
            ASSERT_TRUE(r.x0 == q.range.x0 && r.y0 == q.range.y0 && r.x1 == q.range.x1 && r.y1 == q.range.y1);
        }
    }
}

TEST(ProjectVector, PointLanesEqualTheScalarProjection) {
    const Camera camera = testCamera(64);
    const std::vector<glm::vec3> voxels = testVoxels();
    // Thresholds that make the far third of the voxels points, and most of them; the low-pass
    // as the prefilter order's, the postfilter's small one, and none (the filter of the voxel alone).
    for (const double threshold : {1.0, 4.0, 0.0})  // 0: point mode (every voxel in front of the eye)
        for (const double prefilter : {kPrefilterVariance, 0.1, 0.0}) {
            const RenderMode mode = threshold > 0.0 ? RenderMode::Hybrid : RenderMode::Point;
            ProjectionContext ctx{camera, tables(), 0.1, 0.1, mode, threshold, FootprintPath::Auto, false, prefilter};
            ctx.magnifiedPrefilterVariance = 0.5 * prefilter;
            SCOPED_TRACE(toString(mode) + " threshold " + std::to_string(threshold) + " prefilter " + std::to_string(prefilter));
            test::forEachTarget([&] {
                Coverage cov;  // splats: points taken; offImage: culled points; exact: fallbacks; declined: not points
                checkPointLanes(ctx, voxels, cov);
                EXPECT_GT(cov.splats, 300);
                EXPECT_GT(cov.offImage, 100);
                EXPECT_GT(cov.declined, 300);
            });
        }
}

// The points' lanes serve hybrid and point mode, sphere kernels, --simd on.
TEST(ProjectVector, PointLanesServeHybridAndPointModeWithSimd) {
    const Camera camera = testCamera(64);
    ProjectionContext ctx{camera, tables(), 0.1, 0.1, RenderMode::Hybrid, 1.0, FootprintPath::Auto, false};
    EXPECT_TRUE(pointLaneContext(ctx).has_value());
    ctx.mode = RenderMode::Point;
    EXPECT_TRUE(pointLaneContext(ctx).has_value());
    ctx.vector = false;
    EXPECT_FALSE(pointLaneContext(ctx).has_value());
    ctx.vector = true;
    for (const RenderMode mode : {RenderMode::Splat, RenderMode::Ewa, RenderMode::Swan, RenderMode::None}) {
        ctx.mode = mode;
        EXPECT_FALSE(pointLaneContext(ctx).has_value()) << toString(mode);
    }
}

// A context the lanes do not serve takes the scalar path for every voxel.
TEST(ProjectVector, OnlyServesSphereSplatsWithSimd) {
    const Camera camera = testCamera(64);
    ProjectionContext ctx{camera, tables(), 0.1, 0.1, RenderMode::Hybrid, 1.0, FootprintPath::Auto, false};
    EXPECT_TRUE(splatLaneContext(ctx).has_value());
    ctx.vector = false;
    EXPECT_FALSE(splatLaneContext(ctx).has_value());
    ctx.vector = true;
    for (const RenderMode mode : {RenderMode::Point, RenderMode::Ewa, RenderMode::Swan, RenderMode::None}) {
        ctx.mode = mode;
        EXPECT_FALSE(splatLaneContext(ctx).has_value()) << toString(mode);
    }
    ctx.mode = RenderMode::Hybrid;
    ctx.footprint = FootprintPath::Exact;
    EXPECT_FALSE(splatLaneContext(ctx).has_value());
}

// projectBatch with the lanes and without (--simd off) fills the same window, in hybrid and point mode.
TEST(ProjectVector, ProjectBatchIsTheSameWithAndWithoutLanes) {
    const Camera camera = testCamera(64);
    const std::vector<glm::vec3> voxels = testVoxels();
    VoxelBatch batch;
    for (size_t i = 0; i < voxels.size(); ++i) {
        batch.viewPos.push_back(voxels[i]);
        batch.distance.push_back(std::isfinite(glm::length(voxels[i])) ? glm::length(voxels[i]) : 0.f);
        batch.sigma.push_back(0.1f + float(i % 7));
        batch.color.emplace_back(0.3f, float(i % 3) / 3.f, 1.f);
        batch.spread.push_back(i % 3 == 0 ? 0.25f * float(i % 11) : 0.f);  // aggregates' spread beside voxels'
        batch.members.push_back(1 + uint32_t(i % 4));
    }
    batch.slabBegin = 0, batch.slabEnd = 1000;
    for (const RenderMode mode : {RenderMode::Hybrid, RenderMode::Point}) {
        SCOPED_TRACE(toString(mode));
        ProjectionContext ctx{camera, tables(), 0.1, 0.1, mode, 1.0, FootprintPath::Auto, false};
        ProjectedWindow lanes, scalar;
        const ProjectionCounts a = projectBatch(batch, ctx, lanes);
        ctx.vector = false;
        const ProjectionCounts b = projectBatch(batch, ctx, scalar);
        EXPECT_EQ(a.points, b.points);
        EXPECT_EQ(a.splats, b.splats);
        EXPECT_EQ(a.exactIndexSplats, b.exactIndexSplats);
        EXPECT_EQ(a.drawnVoxels, b.drawnVoxels);
        EXPECT_EQ(a.lodAggregates, b.lodAggregates);
        EXPECT_GT(a.points, 1000);  // both lane paths are exercised (point mode: points alone)
        if (mode == RenderMode::Hybrid) {
            EXPECT_GT(a.splats, 1000);
        }
        ASSERT_NO_FATAL_FAILURE(test::expectSameWindow(lanes, scalar));
    }
}

}  // namespace
}  // namespace vdbsplat

namespace vdbsplat {
namespace {

/// The slab of one distance as projectBatch computed it voxel by voxel before slabsOf: the
/// double quotient, floored by a cast and a compare.
int64_t scalarSlab(float distance, double slabLength, int64_t first, int64_t last) {
    const double x = double(distance) / slabLength;
    const int64_t i = int64_t(x);
    return std::clamp<int64_t>(i - (double(i) > x ? 1 : 0), first, last);
}

// slabsOf against the scalar quotient and floor, for every count of lanes left over and at the
// distances where a floor can go wrong: exact multiples of the slab length, the floats either
// side of them, zero, and the clamps at both ends.
TEST(ProjectVector, SlabsOfEqualsTheScalarFloor) {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> u(0.f, 60.f);
    for (const double length : {0.1, 0.5, 1.0, 0.7853981633974483, 3.0}) {
        std::vector<float> distance;
        for (int k = 0; k < 200; ++k) {
            const float m = float(k * length);
            distance.insert(distance.end(), {m, std::nextafter(m, 0.f), std::nextafter(m, 1e9f), u(rng)});
        }
        distance.push_back(0.f);
        const int64_t first = 3, last = int64_t(45 / length);
        for (const size_t n : {size_t(0), size_t(1), size_t(7), size_t(8), size_t(9), size_t(255), distance.size()}) {
            std::vector<int64_t> slab(n + 1, -777);  // one past n: must stay untouched
            slabsOf(distance.data(), n, length, first, last, slab.data());
            for (size_t i = 0; i < n; ++i)
                ASSERT_EQ(slab[i], scalarSlab(distance[i], length, first, last)) << "length " << length << ", distance " << distance[i];
            EXPECT_EQ(slab[n], -777) << "slabsOf wrote past its n = " << n;
        }
    }
}

}  // namespace
}  // namespace vdbsplat
