// tests/shading/test_shade_leaf.cpp — VoxelShader::shadeLeaf (shading/shade_leaf.h) against the
// voxel-by-voxel factors (shadeDrawn) it must equal bit for bit: leaves beside leaves, active and
// inactive tiles and the background; inactive and non-finite values; an eye far off, beside and
// exactly on a voxel; headlight and a directional light; gradient opacity; an affine transform.
// And in the stream: the same records with the whole-leaf factors as voxel by voxel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "camera/camera.h"
#include "shading/shading_field.h"
#include "support/targets.h"
#include "volume/generate.h"
#include "volume/stream.h"

namespace vdbsplat {
namespace {

/// Leaves of random values (some inactive, one NaN, one +∞) around the leaf at the origin, an
/// active and an inactive tile beside others, and an affine, off-axis index-to-world map.
Volume mixedVolume() {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.05f);
    auto acc = grid->getAccessor();
    uint32_t state = 12345;
    const auto next = [&] { return state = state * 1664525u + 1013904223u, float(state >> 8) / float(1u << 24); };
    for (int i = -8; i < 16; ++i)
        for (int j = -8; j < 16; ++j)
            for (int k = 0; k < 16; ++k) {
                const float u = next();
                if (u < 0.15f) continue;  // left as background
                const openvdb::Coord c(i, j, k);
                acc.setValue(c, 1.3f * next() - 0.15f);  // some beyond [0, 1]: clamped
                if (u < 0.25f) acc.setValueOff(c);
            }
    acc.setValueOn(openvdb::Coord(3, 4, 5), std::numeric_limits<float>::quiet_NaN());
    acc.setValueOn(openvdb::Coord(9, 2, 7), std::numeric_limits<float>::infinity());
    // Beside the leaf at (0, 0, 16)… an active tile, and an inactive one beside (16, 0, 0).
    grid->tree().addTile(1, openvdb::Coord(0, 0, 24), 0.7f, true);
    grid->tree().addTile(1, openvdb::Coord(16, 0, 8), 0.9f, false);
    acc.setValueOn(openvdb::Coord(16, 3, 3), 0.6f);  // a leaf beside (8, 0, 0)
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    m.preScale(openvdb::Vec3d(0.8, 1.1, 0.9));
    m.preRotate(openvdb::math::X_AXIS, 0.3);
    m.preRotate(openvdb::math::Y_AXIS, -0.7);
    m.postTranslate(openvdb::Vec3d(2.5, -1.0, 4.0));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
    return makeVolume(grid, "mixed");
}

ClassificationTable rampTable() {
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float t = float(i) / float(ClassificationTable::kSize - 1);
        entries[size_t(i)] = {glm::vec3(t, 1.f - t, 0.5f), t < 0.1f ? 0.f : 2.f * t};
    }
    return ClassificationTable(entries, 0.f, 1.f);
}

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Every voxel of every leaf: shadeLeaf's factors against shadeDrawn's, bit for bit, where the
/// table may draw the voxel (active, finite, index ≥ transparentBelow), and (1, 0, 1) elsewhere.
void expectEveryLeafAsVoxelByVoxel(const Volume& v, const ClassificationTable& table, const VoxelShader& shader,
                                   uint64_t& lit, uint64_t& skipped, uint64_t& compared) {
    VoxelShader::Accessor acc(*v.tree);
    LeafFactors f;
    for (auto leaf = v.tree->cbeginLeaf(); leaf; ++leaf) {
        ASSERT_TRUE(shader.shadeLeaf(acc, *leaf, f));
        for (openvdb::Index n = 0; n < LeafFactors::kVoxels; ++n) {
            const float value = leaf->getValue(n);
            const float index = std::clamp(value * table.scale() + table.offset(), 0.f, float(ClassificationTable::kSize - 1));
            const bool drawn = leaf->isValueOn(n) && std::isfinite(value) && !(index < table.transparentBelow());
            const openvdb::Vec3f want = drawn ? shader.shadeDrawn(acc, &*leaf, n, leaf->offsetToGlobalCoord(n))
                                              : openvdb::Vec3f(1.f, 0.f, 1.f);
            SCOPED_TRACE(testing::Message() << "leaf " << leaf->origin() << " voxel " << n);
            ASSERT_TRUE(sameBits(f.diffuse[n], want[0])) << f.diffuse[n] << " " << want[0];
            ASSERT_TRUE(sameBits(f.specular[n], want[1])) << f.specular[n] << " " << want[1];
            ASSERT_TRUE(sameBits(f.opacity[n], want[2])) << f.opacity[n] << " " << want[2];
            lit += want[1] > 0.f;
            skipped += !drawn;
            ++compared;
        }
    }
}

TEST(ShadeLeaf, EqualsTheVoxelByVoxelFactorsBitForBit) {
    const Volume v = mixedVolume();
    const ClassificationTable table = rampTable();
    ShadingSettings phong = ShadingSettings::ctPreset();
    ShadingSettings lightAndOpacity = phong;
    lightAndOpacity.hasLight = true, lightAndOpacity.light = glm::dvec3(0.3, -0.8, 0.5);
    lightAndOpacity.gradientOpacity = 25.f, lightAndOpacity.shininess = 7.5f;
    ShadingSettings opacityOnly;
    opacityOnly.gradientOpacity = 40.f;
    const glm::dvec3 onAVoxel(v.indexToWorld * glm::dvec4(2.0, 5.0, 6.0, 1.0));  // the eye exactly at a voxel centre
    const glm::dvec3 eyes[] = {{40.0, -25.0, 60.0}, {3.1, 2.2, 5.7}, onAVoxel};
    if (!leafShadingSupported()) GTEST_SKIP() << "this CPU has no 8-float vectors (voxel-by-voxel shading only)";
    uint64_t lit = 0, skipped = 0, compared = 0;
    test::forEachTarget([&] {  // AVX2 and AVX-512 shade; SSE4 and scalar say they do not
        if (!leafShadingSupported()) return;
        for (const ShadingSettings& s : {phong, lightAndOpacity, opacityOnly})
            for (const glm::dvec3& eye : eyes)
                for (const float hi : {1.f, 0.6f}) {  // two normalisations
                    const VoxelShader shader(v, table, 0.f, hi, eye, s);
                    expectEveryLeafAsVoxelByVoxel(v, table, shader, lit, skipped, compared);
                }
    });
    EXPECT_GT(compared, 100000u);
    EXPECT_GT(lit, compared / 10);  // the specular term is exercised, not just the unshaded lanes
    EXPECT_GT(skipped, compared / 10);  // and voxels the table leaves transparent
}

// In the stream, shaded: every record the same with the whole-leaf factors as voxel by voxel, at a
// framed view (voxels, the vectorised extraction) and a far one (level-of-detail cells through the
// scalar row sums, which add the same numbers in the same order). With the vectorised sums as
// well, the far records agree to float rounding (the sums' own oracle: LeafMoments tests).
TEST(ShadeLeaf, StreamRecordsEqualTheVoxelByVoxelShading) {
    if (!leafShadingSupported()) GTEST_SKIP() << "this CPU has no 8-float vectors (voxel-by-voxel shading only)";
    const Volume v = makeVolume(makeCloud(60000, 3), "cloud");
    const ClassificationTable table = rampTable();
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    for (const double distance : {1.0, 8.0}) {
        CameraSpec spec;
        spec.width = spec.height = 256;
        spec.distance = distance;
        const Camera camera = makeCamera(spec, lo, hi);
        const VoxelShader shader(v, table, 0.f, 1.f, camera.eye(), ShadingSettings::ctPreset());
        const auto records = [&](bool vectorShading, bool vectorSums) {
            StreamOptions o;
            o.vectorShading = vectorShading, o.vectorLeafMoments = vectorSums;
            o.pointBelowPx = 1.0;
            VoxelStream stream(v, camera, table, o, &shader);
            VoxelBatch batch;
            std::vector<float> r;
            while (stream.next(batch))
                for (size_t i = 0; i < batch.size(); ++i)
                    r.insert(r.end(), {batch.viewPos[i].x, batch.viewPos[i].y, batch.viewPos[i].z, batch.sigma[i],
                                       batch.color[i].x, batch.color[i].y, batch.color[i].z});
            return std::pair(r, stream.counts().aggregates);
        };
        SCOPED_TRACE("distance " + std::to_string(distance));
        const auto [scalar, aggregates] = records(false, false);
        EXPECT_GT(scalar.size(), 7 * size_t(1000));
        EXPECT_EQ(records(true, false).first, scalar);
        const auto vectorised = records(true, true).first;
        ASSERT_EQ(vectorised.size(), scalar.size());
        for (size_t i = 0; i < scalar.size(); ++i)
            ASSERT_NEAR(vectorised[i], scalar[i], 1e-5f * std::max(1.f, std::abs(scalar[i]))) << "number " << i;
        if (distance > 4.0) {
            EXPECT_GT(aggregates, 1000u);  // the far view's records are cells
        }
    }
}

}  // namespace
}  // namespace vdbsplat
