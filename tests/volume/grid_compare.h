// tests/volume/grid_compare.h — shared by the grid-loading tests (header only): grids with
// leaves, tiles at every level and non-finite values (mixedGrid), a rotated transform, what
// loadVolume did before any of its fast paths (plainRead: OpenVDB's read, FloatTree's
// converting copy, makeVolume), and bit-for-bit comparisons of trees, volumes and metadata.
#pragma once
#include <gtest/gtest.h>

#include <openvdb/io/File.h>

#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "volume/grid.h"

namespace vdbsplat::test {

using openvdb::Coord;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// Leaves (dense and sparse, NaN and inf among active and inactive values), active tiles at
/// levels 1, 2 and 3 (one of them NaN), inactive tiles that are not the background.
template <typename GridT>
inline typename GridT::Ptr mixedGrid(const std::string& name) {
    using V = typename GridT::ValueType;
    auto g = GridT::create(V(0.25));
    g->setName(name);
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto& tree = g->tree();
    std::mt19937 rng(7);
    for (int i = 0; i < 3000; ++i)
        tree.setValueOn(Coord(int(rng() % 200) - 100, int(rng() % 90), -int(rng() % 50)), V(0.001 * (rng() % 997)));
    tree.setValueOn(Coord(3, 4, 5), V(kNaN));
    tree.setValueOn(Coord(-9, 4, 5), V(kInf));
    tree.setValueOn(Coord(-9, 5, 5), V(-kInf));
    tree.setValueOff(Coord(3, 5, 5), V(kNaN));     // inactive: kept as it is
    tree.setValueOn(Coord(17, 17, 17), V(-3.5));   // the minimum
    tree.addTile(1, Coord(512, 0, 0), V(0.75), true);
    tree.addTile(1, Coord(520, 0, 0), V(-1.0), false);  // inactive, not the background
    tree.addTile(2, Coord(1024, 0, 0), V(2.5), true);   // the maximum
    tree.addTile(2, Coord(1024, 128, 0), V(kNaN), true);
    tree.addTile(3, Coord(-8192, 0, 0), V(1.5), true);
    tree.addTile(3, Coord(-8192, 4096, 0), V(-2.0), false);
    return g;
}

inline openvdb::math::Transform::Ptr rotated() {
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    m.setToRotation(openvdb::math::Vec3d(0, 1, 1), 0.4);
    m.preScale(openvdb::math::Vec3d(0.3));
    m.setTranslation(openvdb::math::Vec3d(1, -2, 3));
    return openvdb::math::Transform::createLinearTransform(m);
}

inline bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Same tree: background, node counts, every leaf (origin, mask, all 512 values bit for bit),
/// every tile (depth, state, value bit for bit).
inline void expectSameTree(const openvdb::FloatTree& want, const openvdb::FloatTree& got) {
    EXPECT_TRUE(sameBits(want.background(), got.background()));
    EXPECT_EQ(want.nodeCount(), got.nodeCount());
    EXPECT_EQ(want.leafCount(), got.leafCount());
    EXPECT_EQ(want.activeTileCount(), got.activeTileCount());
    EXPECT_EQ(want.activeVoxelCount(), got.activeVoxelCount());
    for (auto leaf = want.cbeginLeaf(); leaf; ++leaf) {
        const auto* other = got.probeConstLeaf(leaf->origin());
        ASSERT_NE(other, nullptr) << leaf->origin();
        EXPECT_EQ(leaf->getValueMask(), other->getValueMask()) << leaf->origin();
        EXPECT_EQ(std::memcmp(leaf->buffer().data(), other->buffer().data(), 4 * leaf->SIZE), 0) << leaf->origin();
    }
    auto it = want.cbeginValueAll();
    it.setMaxDepth(it.getLeafDepth() - 1);
    int tiles = 0;
    for (; it; ++it) {
        const Coord c = it.getCoord();
        float value = 0.f;
        const bool on = got.probeValue(c, value);
        EXPECT_EQ(got.getValueDepth(c), int(it.getDepth())) << c;
        EXPECT_EQ(on, it.isValueOn()) << c;
        EXPECT_TRUE(sameBits(value, *it)) << c << ": " << value << " vs " << *it;
        ++tiles;
    }
    EXPECT_GT(tiles, 0);
}

/// What loadVolume did before: a plain read, FloatTree's converting copy, makeVolume.
inline Volume plainRead(const std::string& file, const std::string& name) {
    openvdb::io::File f(file);
    f.open(false);
    openvdb::GridBase::Ptr base = f.readGrid(name);
    f.close();
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) {
        auto d = openvdb::gridPtrCast<openvdb::DoubleGrid>(base);
        grid = openvdb::FloatGrid::create(std::make_shared<openvdb::FloatTree>(d->tree()));
        grid->setTransform(d->transform().copy());
        grid->setName(d->getName());
        grid->setGridClass(d->getGridClass());
    }
    return makeVolume(grid, file);
}

inline void expectSameVolume(const Volume& want, const Volume& got) {
    expectSameTree(*want.tree, *got.tree);
    EXPECT_EQ(want.map->type(), got.map->type());
    EXPECT_TRUE(want.map->isEqual(*got.map));
    EXPECT_TRUE(sameTransform(want, got));
    EXPECT_EQ(want.name, got.name);
    EXPECT_EQ(want.voxelSize, got.voxelSize);
    EXPECT_EQ(want.indexToWorld, got.indexToWorld);
    EXPECT_EQ(want.worldToIndex, got.worldToIndex);
    EXPECT_EQ(want.indexBox, got.indexBox);
    EXPECT_EQ(want.activeVoxels, got.activeVoxels);
    EXPECT_EQ(want.nonFiniteCount, got.nonFiniteCount);
    EXPECT_TRUE(sameBits(want.valueMin, got.valueMin)) << want.valueMin << " vs " << got.valueMin;
    EXPECT_TRUE(sameBits(want.valueMax, got.valueMax)) << want.valueMax << " vs " << got.valueMax;
}

/// Same metadata: every item of @p want in @p got with the same type and value, and no other.
inline void expectSameMetadata(const openvdb::MetaMap& want, const openvdb::MetaMap& got) {
    EXPECT_EQ(want.metaCount(), got.metaCount());
    for (auto it = want.beginMeta(); it != want.endMeta(); ++it) {
        const openvdb::Metadata::ConstPtr other = got[it->first];
        ASSERT_TRUE(other) << it->first;
        EXPECT_EQ(it->second->typeName(), other->typeName()) << it->first;
        EXPECT_EQ(it->second->str(), other->str()) << it->first;
    }
}

}  // namespace vdbsplat::test
