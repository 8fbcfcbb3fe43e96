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

/// The default framing of @p v at @p size² pixels and @p distance times the framing distance.
Camera framedCamera(const Volume& v, int size, double distance = 1.0) {
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = size;
    spec.distance = distance;
    return makeCamera(spec, lo, hi);
}

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
    const Camera camera = framedCamera(v, 128);
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
    const Camera camera = framedCamera(v, 96);  // framed: everything visible
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
    const Camera camera = framedCamera(v, 64, 0.6);
    const ClassificationTable table = constantTable(0.3f);
    const Streamed a = streamAll(v, camera, table), b = streamAll(v, camera, table);
    ASSERT_EQ(a.batches.size(), b.batches.size());
    for (size_t k = 0; k < a.batches.size(); ++k) {
        ASSERT_EQ(a.batches[k].viewPos, b.batches[k].viewPos);
        ASSERT_EQ(a.batches[k].slabBegin, b.batches[k].slabBegin);
    }
}

// maxWindowVoxels bounds the windows: a window over the bound makes the next one half as
// many slabs deep (down to one), so memory follows the densest slab rather than the densest
// eight. The same voxels come out in the same slabs either way: windows split only at slab
// boundaries.
TEST(Stream, WindowsNarrowWhileOverTheVoxelBound) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 96);
    const ClassificationTable table = constantTable(0.2f);
    StreamOptions narrow;
    narrow.minWindowVoxels = 1;
    narrow.maxWindowVoxels = 3000;
    StreamOptions wide = narrow;
    wide.maxWindowVoxels = size_t(1) << 30;

    struct Window { size_t voxels; int64_t slabs; };
    // Every voxel tagged with its slab; and no slab may be split between two windows (the
    // compositor flushes a slab's points when its window ends).
    using Tagged = std::tuple<int64_t, float, float, float>;
    const auto run = [&](const StreamOptions& o, std::vector<Window>& windows) {
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch;
        std::vector<Tagged> voxels;
        std::map<int64_t, size_t> windowOfSlab;
        size_t largest = 0;
        while (stream.next(batch)) {
            windows.push_back({batch.size(), batch.slabEnd - batch.slabBegin});
            largest = std::max(largest, batch.size());
            for (size_t i = 0; i < batch.size(); ++i) {
                const int64_t slab = int64_t(std::floor(batch.distance[i] / stream.slabLength()));
                const auto [it, fresh] = windowOfSlab.try_emplace(slab, windows.size());
                EXPECT_EQ(it->second, windows.size()) << "slab " << slab << " split between windows";
                const glm::vec3 p = batch.viewPos[i];
                voxels.emplace_back(slab, p.x, p.y, p.z);
            }
        }
        EXPECT_EQ(stream.largestWindow(), largest);
        EXPECT_EQ(stream.windows(), windows.size());
        std::sort(voxels.begin(), voxels.end());
        return voxels;
    };
    std::vector<Window> n, w;
    EXPECT_EQ(run(narrow, n), run(wide, w));  // the same voxels in the same slabs
    const auto largest = [](const std::vector<Window>& ws) {
        size_t m = 0;
        for (const Window& x : ws) m = std::max(m, x.voxels);
        return m;
    };
    EXPECT_GT(n.size(), 2 * w.size());
    EXPECT_LT(largest(n), largest(w) / 2);
    int narrowed = 0;
    for (size_t k = 0; k + 1 < n.size(); ++k)
        if (n[k].voxels > narrow.maxWindowVoxels && n[k].slabs > 1) {
            EXPECT_EQ(n[k + 1].slabs, n[k].slabs / 2) << "window " << k;
            ++narrowed;
        }
    EXPECT_GT(narrowed, 0);
    for (const Window& x : w) EXPECT_EQ(x.slabs, wide.slabsPerWindow);  // never narrowed
}

}  // namespace
}  // namespace vdbsplat
