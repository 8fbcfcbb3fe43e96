// tests/volume/test_emission.cpp — the emission grid's pieces (volume/emission.h): the
// blackbody colour map, the baked emission table, attaching a grid (the same-transform check and
// the union of the topologies), and the explosion generator.
#include <gtest/gtest.h>

#include <openvdb/math/Transform.h>

#include "util/error.h"
#include "volume/emission.h"
#include "volume/generate.h"

namespace vdbsplat {
namespace {

// The sRGB white point is D65, a daylight spectrum close to a 6504 K blackbody: their linear
// sRGB agree within 5 % (measured 1.042, 0.984, 1.035: the Planckian locus passes just beside D65).
TEST(Emission, BlackbodyNearD65IsAboutWhite) {
    const glm::vec3 c = blackbodyRgb(6504.0);
    EXPECT_NEAR(c.x, 1.0, 0.05);
    EXPECT_NEAR(c.y, 1.0, 0.05);
    EXPECT_NEAR(c.z, 1.0, 0.05);
    // Luminance 1 (Y = 0.2126 R + 0.7152 G + 0.0722 B) where no channel is clipped.
    EXPECT_NEAR(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z, 1.0, 2e-3);
}

TEST(Emission, BlackbodyReddensAsItCools) {
    double previousBlueOverRed = 1e9;
    for (double T : {12000.0, 6500.0, 4000.0, 2500.0, 1500.0}) {
        const glm::vec3 c = blackbodyRgb(T);
        EXPECT_GE(c.x, 0.f);
        EXPECT_GE(c.z, 0.f);
        const double ratio = c.z / c.x;
        EXPECT_LT(ratio, previousBlueOverRed) << T << " K";
        previousBlueOverRed = ratio;
    }
    const glm::vec3 ember = blackbodyRgb(1500.0);
    EXPECT_GT(ember.x, ember.y);
    EXPECT_GT(ember.y, ember.z);
}

TEST(Emission, BlackbodyMapIsDarkAtTheRangeStartAndScaledAtItsEnd) {
    EXPECT_EQ(blackbodyEmission(0.0, 1500.0, 6500.0, 3.0), glm::vec3(0.f));
    const glm::vec3 top = blackbodyEmission(1.0, 1500.0, 6500.0, 3.0), white = blackbodyRgb(6500.0) * 3.f;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(top[k], white[k], 1e-5f);
    // Brightness (T⁴ − lo⁴)/(hi⁴ − lo⁴) at the middle of the range (T = 4000 K).
    const glm::vec3 mid = blackbodyEmission(0.5, 1500.0, 6500.0, 1.0), colour = blackbodyRgb(4000.0);
    const double brightness = (std::pow(4000.0, 4) - std::pow(1500.0, 4)) / (std::pow(6500.0, 4) - std::pow(1500.0, 4));
    EXPECT_NEAR(mid.y / colour.y, brightness, 1e-4);
}

TEST(Emission, BakedTableFollowsTheMapOverTheGridRange) {
    EmissionSettings s;
    s.grid = "temperature";
    s.scale = 2.0;
    // Values beyond [0, 1]: normalised from the grid's [min, max] = [300, 2300].
    const ClassificationTable t = bakeEmission(s, nullptr, 300.f, 2300.f, 1.0);
    EXPECT_EQ(t(300.f).color, glm::vec3(0.f));
    const glm::vec3 top = t(2300.f).color, want = blackbodyEmission(1.0, s.kelvinLo, s.kelvinHi, 2.0);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(top[k], want[k], 1e-4f);
    const glm::vec3 mid = t(1300.f).color, wantMid = blackbodyEmission(0.5, s.kelvinLo, s.kelvinHi, 2.0);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(mid[k], wantMid[k], 1e-3f * std::max(1.f, wantMid[k]));
    EXPECT_EQ(t(300.f).sigma, 0.f);
    // A transfer function: its emission σ·c without its extinction, times the scale.
    s.map = "fire";
    const TransferFunction fire = TransferFunction::preset("fire");
    const ClassificationTable f = bakeEmission(s, &fire, 0.f, 1.f, 1.0);
    const Classified at = fire.evaluate(0.75f);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f(0.75f).color[k], 2.f * at.sigma * at.color[k], 1e-3f);
}

openvdb::FloatGrid::Ptr gridOn(const std::vector<openvdb::Coord>& voxels, float value, const std::string& name,
                               openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(1.0)) {
    auto g = openvdb::FloatGrid::create(0.f);
    g->setName(name);
    g->setTransform(xform);
    for (const auto& c : voxels) g->tree().setValueOn(c, value);
    return g;
}

TEST(Emission, AttachUnitesTheTopologiesWithTheDensityBackground) {
    initOpenVdb();
    auto density = gridOn({openvdb::Coord(0), openvdb::Coord(1, 0, 0)}, 0.7f, "density");
    // An inactive value that is not the background: the emission-only voxel must not take it.
    density->tree().setValueOff(openvdb::Coord(5, 0, 0), 0.9f);
    Volume v = makeVolume(density, "d");
    attachEmission(v, makeVolume(gridOn({openvdb::Coord(1, 0, 0), openvdb::Coord(5, 0, 0)}, 2.f, "temperature"), "e"));
    ASSERT_TRUE(v.emission);
    EXPECT_EQ(v.emission->outsideDensity, 1u);
    EXPECT_EQ(v.activeVoxels, 3u);
    EXPECT_EQ(v.tree->activeVoxelCount(), 3u);
    EXPECT_TRUE(v.tree->isValueOn(openvdb::Coord(5, 0, 0)));
    EXPECT_EQ(v.tree->getValue(openvdb::Coord(5, 0, 0)), 0.f);
    EXPECT_EQ(v.tree->getValue(openvdb::Coord(1, 0, 0)), 0.7f);
    EXPECT_EQ(v.indexBox.max().x(), 5);
    // The value range stays the density's.
    EXPECT_EQ(v.valueMin, 0.7f);
    EXPECT_EQ(v.valueMax, 0.7f);
}

TEST(Emission, AttachRefusesAnotherTransformNamingBothGrids) {
    initOpenVdb();
    Volume v = makeVolume(gridOn({openvdb::Coord(0)}, 1.f, "density"), "d");
    for (const auto& xform : {openvdb::math::Transform::createLinearTransform(2.0),
                              openvdb::math::Transform::createLinearTransform(1.0)}) {
        if (xform->voxelSize()[0] == 1.0) xform->postTranslate(openvdb::Vec3d(0.5, 0.0, 0.0));
        Volume e = makeVolume(gridOn({openvdb::Coord(0)}, 1.f, "heat", xform), "e");
        e.file = "f.vdb";
        try {
            attachEmission(v, e);
            ADD_FAILURE() << "accepted another transform";
        } catch (const Error& err) {
            const std::string what = err.what();
            EXPECT_EQ(what.rfind("f.vdb: emission grid 'heat'", 0), 0u) << what;
            EXPECT_NE(what.find("density grid 'density'"), std::string::npos) << what;
        }
    }
    EXPECT_FALSE(v.emission);
}

TEST(Emission, ExplosionIsDeterministicAndHotOnlyInsideTheSmoke) {
    initOpenVdb();
    const auto a = makeExplosion(24, 3), b = makeExplosion(24, 3), c = makeExplosion(24, 4);
    ASSERT_EQ(a.size(), 2u);
    EXPECT_EQ(a[0]->getName(), "density");
    EXPECT_EQ(a[1]->getName(), "temperature");
    const auto same = [](const openvdb::FloatGrid& x, const openvdb::FloatGrid& y) {
        if (x.activeVoxelCount() != y.activeVoxelCount()) return false;
        for (auto it = x.cbeginValueOn(); it; ++it)
            if (y.tree().getValue(it.getCoord()) != *it || !y.tree().isValueOn(it.getCoord())) return false;
        return true;
    };
    EXPECT_TRUE(same(*a[0], *b[0]));
    EXPECT_TRUE(same(*a[1], *b[1]));
    EXPECT_FALSE(same(*a[0], *c[0]));
    EXPECT_GT(a[1]->activeVoxelCount(), 100u);
    EXPECT_LT(a[1]->activeVoxelCount(), a[0]->activeVoxelCount());
    for (auto it = a[1]->cbeginValueOn(); it; ++it) {
        ASSERT_TRUE(a[0]->tree().isValueOn(it.getCoord())) << it.getCoord();
        ASSERT_GT(*it, 0.f);
        ASSERT_LE(*it, 1.f);
    }
    GenerateOptions o;
    o.kind = "explosion";
    o.res = 24;
    o.seed = 3;
    EXPECT_EQ(generateGrids(o).size(), 2u);
}

}  // namespace
}  // namespace vdbsplat
