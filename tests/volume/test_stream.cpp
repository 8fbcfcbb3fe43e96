// tests/volume/test_stream.cpp — the depth-ordered voxel stream (DESIGN §5) against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "camera/camera.h"
#include "volume/generate.h"
#include "volume/grid.h"
#include "volume/stream.h"

namespace vdbsplat {
namespace {

ClassificationTable constantTable(float sigma) {
    return ClassificationTable(std::vector<Classified>(ClassificationTable::kSize, Classified{glm::vec3(1.f), sigma}),
                               0.f, 1.f);
}

/// A cloud: sparse, irregular leaves and values; deterministic.
const Volume& cloud() {
    static const Volume v = makeVolume(makeCloud(200000, 7), "cloud");
    return v;
}

struct Streamed {
    std::vector<VoxelBatch> batches;
    uint64_t voxels = 0, culled = 0;
    size_t largestBatch = 0;
};

Streamed streamAll(const Volume& v, const Camera& camera, const ClassificationTable& table) {
    VoxelStream stream(v, camera, table);
    Streamed s;
    VoxelBatch batch;
    while (stream.next(batch)) {
        s.voxels += batch.size();
        s.largestBatch = std::max(s.largestBatch, batch.size());
        s.batches.push_back(batch);
    }
    s.culled = stream.culledVoxels();
    return s;
}

// Windows come out front to back: window slab ranges increase, every voxel lies in its
// window's slabs, and the view positions are the camera's transform of the voxel centres.
TEST(Stream, WindowsAreFrontToBackAndVoxelsInTheirSlabs) {
    const Volume& v = cloud();
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = 128;
    const Camera camera = makeCamera(spec, lo, hi);
    const ClassificationTable table = constantTable(0.2f);
    VoxelStream stream(v, camera, table);
    VoxelBatch batch;
    int64_t lastEnd = std::numeric_limits<int64_t>::min();
    int windows = 0;
    while (stream.next(batch)) {
        ++windows;
        EXPECT_GE(batch.slabBegin, lastEnd);
        EXPECT_LT(batch.slabBegin, batch.slabEnd);
        lastEnd = batch.slabEnd;
        for (size_t i = 0; i < batch.size(); ++i) {
            const auto slab = int64_t(std::floor(batch.distance[i] / stream.slabLength()));
            ASSERT_GE(slab, batch.slabBegin - 1) << "voxel before its window";  // float rounding at the edge
            ASSERT_LE(slab, batch.slabEnd) << "voxel after its window";
            ASSERT_NEAR(batch.distance[i], glm::length(batch.viewPos[i]), 1e-3f * batch.distance[i]);
        }
    }
    EXPECT_GE(windows, 5);  // 200k voxels in windows of about 32k: streamed, not all at once
}

// Every active voxel in front of the eye and inside the frustum comes out exactly once, with its
// classification; σ = 0 voxels never do.
TEST(Stream, EveryVisibleVoxelExactlyOnce) {
    const Volume& v = cloud();
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = 96;
    const Camera camera = makeCamera(spec, lo, hi);  // framed: everything visible
    const ClassificationTable table = constantTable(0.2f);
    const Streamed s = streamAll(v, camera, table);
    EXPECT_EQ(s.voxels + s.culled, v.activeVoxels);
    EXPECT_EQ(s.voxels, v.activeVoxels);  // the framed view sees every voxel
    std::map<std::tuple<int, int, int>, int> seen;
    for (const VoxelBatch& b : s.batches)
        for (size_t i = 0; i < b.size(); ++i) {
            EXPECT_FLOAT_EQ(b.sigma[i], 0.2f);
            const glm::vec3 p = b.viewPos[i];
            ++seen[{int(std::lround(p.x * 64)), int(std::lround(p.y * 64)), int(std::lround(p.z * 64))}];
        }
    for (const auto& [key, count] : seen) ASSERT_EQ(count, 1);
    EXPECT_EQ(seen.size(), v.activeVoxels);
    // A transparent transfer function streams nothing.
    EXPECT_EQ(streamAll(v, camera, constantTable(0.f)).voxels, 0u);
}

// Behind the eye and outside the frustum costs almost nothing: an eye inside the volume looking
// out along +x streams only the voxels in its view cone (with the kernel margin) and culls the
// rest by whole blocks.
TEST(Stream, CullsBehindTheEyeAndOutsideTheFrustum) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    grid->denseFill(openvdb::CoordBBox({-64, -64, -64}, {63, 63, 63}), 1.f, true);
    grid->tree().voxelizeActiveTiles();
    const Volume v = makeVolume(grid, "cube");
    const Camera camera({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 20.0, 64, 64);
    const Streamed s = streamAll(v, camera, constantTable(0.01f));
    EXPECT_EQ(s.voxels + s.culled, v.activeVoxels);
    // The 20° cone out to x = 64 holds about (64³/3)·(2·tan10°)² ≈ 0.012 of the 128³ voxels.
    EXPECT_LT(double(s.voxels), 0.05 * double(v.activeVoxels));
    EXPECT_GT(double(s.voxels), 0.005 * double(v.activeVoxels));
    // Nothing streamed lies behind the eye beyond the kernel margin, and the windows stay small.
    for (const VoxelBatch& b : s.batches)
        for (size_t i = 0; i < b.size(); ++i) ASSERT_GT(b.viewPos[i].z, -2.0f - 8.0f * std::sqrt(3.0f));
    EXPECT_LT(s.largestBatch, v.activeVoxels / 20);
}

// The batches are a function of the scene only (ordering inside a window included), so
// everything downstream is deterministic.
TEST(Stream, SameInputSameBatches) {
    const Volume& v = cloud();
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = 64;
    spec.distance = 0.6;
    const Camera camera = makeCamera(spec, lo, hi);
    const ClassificationTable table = constantTable(0.3f);
    const Streamed a = streamAll(v, camera, table), b = streamAll(v, camera, table);
    ASSERT_EQ(a.batches.size(), b.batches.size());
    for (size_t k = 0; k < a.batches.size(); ++k) {
        ASSERT_EQ(a.batches[k].viewPos, b.batches[k].viewPos);
        ASSERT_EQ(a.batches[k].slabBegin, b.batches[k].slabBegin);
    }
}

}  // namespace
}  // namespace vdbsplat
