// tests/support/projection.h — shared by the projection and compositor tests (header only): the
// footprint tables built once per test binary, and the camera that frames the box [−8, 8]³.
#pragma once
#include <gtest/gtest.h>

#include "camera/camera.h"
#include "composite/primitive.h"
#include "footprint/tables.h"

namespace vdbsplat::test {

/// @brief The default footprint tables (buildTables()), built on first use and kept.
inline const Tables& sharedTables() {
    static const Tables t = buildTables();
    return t;
}

/// @brief A @p size × @p size camera framing the box [−8, 8]³ (makeCamera's default view).
inline Camera boxCamera(int size) {
    CameraSpec spec;
    spec.width = spec.height = size;
    return makeCamera(spec, glm::dvec3(-8.0), glm::dvec3(8.0));
}

/// @brief Asserts that two projected windows hold the same primitives, bit for bit: every order
/// key, and every drawn primitive's depth, member count, record, tiles and exact index map (a slot
/// not drawn holds nothing but its order key: ProjectedWindow's compaction).
/// Call through ASSERT_NO_FATAL_FAILURE.
inline void expectSameWindow(const ProjectedWindow& a, const ProjectedWindow& b) {
    ASSERT_EQ(a.size, b.size);
    ASSERT_EQ(a.slabBase, b.slabBase);
    ASSERT_EQ(a.slabEnd, b.slabEnd);
    for (size_t i = 0; i < a.size; ++i) {
        ASSERT_EQ(a.order[i], b.order[i]) << i;
        if (a.order[i] == ProjectedWindow::kNotDrawn) continue;
        ASSERT_EQ(a.depth[i], b.depth[i]) << i;
        ASSERT_EQ(a.members[i], b.members[i]) << i;
        const PrimitiveRecord &p = a.records[i], &q = b.records[i];
        ASSERT_EQ(p.kind, q.kind) << i;
        ASSERT_EQ(p.centre, q.centre) << i;
        ASSERT_EQ(p.shape, q.shape) << i;
        ASSERT_EQ(p.scale, q.scale) << i;
        ASSERT_EQ(p.sin2Alpha, q.sin2Alpha) << i;
        ASSERT_EQ(p.color, q.color) << i;
        ASSERT_EQ(p.slab, q.slab) << i;
        ASSERT_TRUE(p.range.x0 == q.range.x0 && p.range.y0 == q.range.y0 && p.range.x1 == q.range.x1 &&
                    p.range.y1 == q.range.y1) << i;
        ASSERT_EQ(a.tiles[i], b.tiles[i]) << i;
        ASSERT_EQ(p.hasExactMap, q.hasExactMap) << i;
        if (p.hasExactMap) {
            ASSERT_TRUE(a.exactMap(i) == b.exactMap(i)) << i;
        }
    }
}

}  // namespace vdbsplat::test
