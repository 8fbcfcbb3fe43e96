// tests/support/readers.h — shared by the convert readers' tests (header only): the fixtures
// of tests/data/readers/ (written by VTK and Teem, see make-fixtures.py), the raw oracle they
// must match, and a voxel-for-voxel grid comparison.
#pragma once
#include <gtest/gtest.h>

#include <string>

#include "volume/raw.h"

namespace vdbsplat::test {

/// @brief The path of a fixture in tests/data/readers/.
inline std::string fixture(const std::string& name) {
    return std::string(VDBSPLAT_SOURCE_DIR) + "/tests/data/readers/" + name;
}

/// @brief The fixture volume (7 x 5 x 4) of @p kind ("u8", "u16", "i16", "f32") converted as raw.
inline openvdb::FloatGrid::Ptr rawOracle(const std::string& kind, double threshold = 0.0) {
    RawSpec spec;
    spec.dims = {7, 5, 4};
    spec.type = kind == "u8" ? RawType::UInt8 : kind == "u16" ? RawType::UInt16
              : kind == "i16" ? RawType::Int16 : RawType::Float32;
    spec.threshold = threshold;
    return convertRaw(fixture("vol_" + kind + ".raw"), spec);
}

/// @brief Same active voxels with exactly the same values (and at least one of them).
inline void expectSameVoxels(const openvdb::FloatGrid& expected, const openvdb::FloatGrid& actual,
                             const std::string& context) {
    ASSERT_GT(expected.activeVoxelCount(), 0u) << context;
    EXPECT_EQ(actual.activeVoxelCount(), expected.activeVoxelCount()) << context;
    auto acc = actual.getConstAccessor();
    for (auto it = expected.cbeginValueOn(); it; ++it) {
        ASSERT_TRUE(acc.isValueOn(it.getCoord())) << context << " at " << it.getCoord();
        ASSERT_EQ(acc.getValue(it.getCoord()), *it) << context << " at " << it.getCoord();
    }
}

/// @brief Where index @p ijk lands in world space under @p grid's transform.
inline openvdb::Vec3d worldOf(const openvdb::FloatGrid& grid, const openvdb::Vec3d& ijk) {
    return grid.transform().indexToWorld(ijk);
}

}  // namespace vdbsplat::test
