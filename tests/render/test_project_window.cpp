// tests/render/test_project_window.cpp — projectWindow, the projection of a window read where the
// stream left its records (StreamWindow: runs of the extraction chunks, of the pending records and
// of the records taken from blocks across the window's edge), against its slow, obvious form: the
// window copied out into one VoxelBatch (StreamWindow::copyTo) and projected by projectBatch. Every
// primitive must be the same, bit for bit, in every window of a stream of many windows.
#include <gtest/gtest.h>

#include <set>

#include "camera/camera.h"
#include "render/project.h"
#include "support/projection.h"
#include "volume/generate.h"
#include "volume/stream.h"

namespace vdbsplat {
namespace {

struct Case {
    const char* name;
    double distance;  ///< of the framing distance: 1 framed (splats), 2.5 and 6 farther (points, aggregates)
    RenderMode mode;
    bool vector;
    double lodCellPx = 1.0;  ///< StreamOptions::lodCellPx (0: every voxel its own record)
};

class ProjectWindow : public ::testing::TestWithParam<Case> {};

TEST_P(ProjectWindow, EqualsTheWindowCopiedOutAndProjected) {
    const Case c = GetParam();
    static const Volume v = makeVolume(makeCloud(150000, 11), "cloud");
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = 96;
    spec.distance = c.distance;
    const Camera camera = makeCamera(spec, lo, hi);
    const ClassificationTable table(std::vector<Classified>(ClassificationTable::kSize, Classified{glm::vec3(0.8f, 0.5f, 0.2f), 0.3f}),
                                    0.f, 1.f);
    StreamOptions options;
    // Many windows, many blocks across their edges.
    options.minWindowVoxels = 512, options.maxWindowVoxels = 8192, options.slabsPerWindow = 4;
    options.pointBelowPx = c.mode == RenderMode::Point ? INFINITY : 1.0;
    options.lodCellPx = c.lodCellPx;
    VoxelStream stream(v, camera, table, options);
    ProjectionContext ctx{camera, test::sharedTables(), v.voxelSize, stream.slabLength(), c.mode, 1.0, FootprintPath::Auto, false};
    ctx.vector = c.vector;
    StreamWindow window;
    VoxelBatch copied;
    ProjectedWindow inPlace, fromCopy;
    size_t windows = 0, records = 0, aggregates = 0, multiBuffer = 0;
    while (stream.next(window)) {
        ++windows;
        size_t taken = 0;
        std::set<const VoxelBatch*> buffers;
        for (const WindowSource& s : window.sources) {
            ASSERT_EQ(s.first, taken);
            ASSERT_GT(s.count, 0u);
            taken += s.count;
            buffers.insert(s.records);
        }
        multiBuffer += buffers.size() >= 2 ? 1 : 0;
        ASSERT_EQ(taken, window.size);
        window.copyTo(copied, false);
        ASSERT_EQ(copied.size(), window.size);
        const ProjectionCounts a = projectWindow(window, ctx, inPlace);
        const ProjectionCounts b = projectBatch(copied, ctx, fromCopy);
        EXPECT_EQ(a.points, b.points);
        EXPECT_EQ(a.splats, b.splats);
        EXPECT_EQ(a.drawnVoxels, b.drawnVoxels);
        EXPECT_EQ(a.lodAggregates, b.lodAggregates);
        aggregates += a.lodAggregates;
        ASSERT_NO_FATAL_FAILURE(test::expectSameWindow(inPlace, fromCopy));
        records += window.size;
    }
    EXPECT_GT(windows, 3u);
    EXPECT_GT(multiBuffer, 1u) << "no window read from several buffers: the test does not reach the runs";
    EXPECT_GT(records, 1000u);
    if (c.lodCellPx > 0.0 && c.distance > 2.0) {
        EXPECT_GT(aggregates, 0u) << "no level-of-detail cell in the case meant for them";
    }
}

INSTANTIATE_TEST_SUITE_P(Views, ProjectWindow,
                         ::testing::Values(Case{"framed_hybrid", 1.0, RenderMode::Hybrid, true},
                                           Case{"framed_scalar", 1.0, RenderMode::Hybrid, false},
                                           Case{"far_points", 6.0, RenderMode::Hybrid, true, 0.0},
                                           Case{"aggregates", 2.5, RenderMode::Hybrid, true, 1.0},
                                           Case{"framed_points", 1.0, RenderMode::Point, true}),
                         [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

}  // namespace
}  // namespace vdbsplat
