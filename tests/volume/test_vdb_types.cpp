// tests/volume/test_vdb_types.cpp — what vdbsplat answers about a .vdb file's type names without
// libopenvdb (volume/vdb_types.h) is what OpenVDB's own registries answer: the fixed sizes of
// metadata types, the registered grid types, and the linear maps read from Transform::write's
// bytes (same map type, same values, the same matrix bit for bit, the same refusal of a
// singular matrix).
#include <gtest/gtest.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <cstring>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "volume/grid.h"
#include "volume/vdb_check.h"
#include "volume/vdb_types.h"

namespace vdbsplat {
namespace {

/// OpenVDB's answer: the bytes its reader takes for a value of @p type, as checkVdbStructure
/// asked before (nothing for "string" and unregistered types).
std::optional<uint64_t> openVdbFixedBytes(const std::string& type) {
    if (type == "string" || !openvdb::Metadata::isRegisteredType(type)) return std::nullopt;
    return openvdb::Metadata::createMetadata(type)->size();
}

TEST(VdbTypes, FixedMetadataSizesAreOpenVdbs) {
    initOpenVdb();  // as every OpenVDB read: "__delayedload" unregistered
    const std::vector<std::string> names = {
        // registered by openvdb::initialize() and points::internal::initialize()
        "bool", "double", "float", "int32", "int64", "string", "vec2i", "vec2s", "vec2d", "vec3i", "vec3s",
        "vec3d", "vec4i", "vec4s", "vec4d", "mat4s", "mat4d", "ptidx32", "ptidx64", "ptdataidx32",
        "ptdataidx64", "__delayedload",
        // not registered
        "", "half", "vec3h", "mat3s", "mat3d", "quats", "quatd", "int16", "uint32", "vec2h", "Vec3d", "mat4",
        "ptidx16", "unknown"};
    int fixed = 0;
    for (const std::string& name : names) {
        EXPECT_EQ(fixedMetadataBytes(name), openVdbFixedBytes(name)) << "'" << name << "'";
        fixed += fixedMetadataBytes(name).has_value();
    }
    EXPECT_EQ(fixed, 20);
    EXPECT_EQ(fixedMetadataBytes("mat4d"), 128u);
    EXPECT_EQ(fixedMetadataBytes("ptdataidx64"), 8u);
}

TEST(VdbTypes, GridTypesAreOpenVdbsRegistry) {
    initOpenVdb();
    const std::vector<std::string> registered = {
        openvdb::FloatGrid::gridType(),  openvdb::DoubleGrid::gridType(), openvdb::Int32Grid::gridType(),
        openvdb::Int64Grid::gridType(),  openvdb::BoolGrid::gridType(),   openvdb::MaskGrid::gridType(),
        openvdb::Vec3SGrid::gridType(),  openvdb::Vec3DGrid::gridType(),  openvdb::Vec3IGrid::gridType(),
        openvdb::tools::PointIndexGrid::gridType(), openvdb::points::PointDataGrid::gridType()};
    for (const std::string& type : registered) {
        EXPECT_TRUE(openvdb::GridBase::isRegistered(type)) << type;
        EXPECT_TRUE(isRegisteredGridType(type)) << type;
    }
    for (const std::string type : {"", "Tree_float_5_4_3_HalfFloat", "Tree_vec2s_5_4_3", "Tree_float_4_4_3",
                                   "Tree_string_5_4_3", "Tree_half_5_4_3", "Tree_float"}) {
        EXPECT_EQ(isRegisteredGridType(type), openvdb::GridBase::isRegistered(type)) << type;
        EXPECT_FALSE(isRegisteredGridType(type)) << type;
    }
}

/// Transform::write's bytes of @p transform, split into the map's type name and its data.
std::pair<std::string, std::string> writtenMap(const openvdb::math::Transform& transform) {
    std::ostringstream out;
    transform.write(out);
    const std::string bytes = out.str();
    uint32_t length = 0;
    std::memcpy(&length, bytes.data(), 4);  // openvdb::writeString: a 32-bit length, then the characters
    return {bytes.substr(4, length), bytes.substr(4 + length)};
}

/// OpenVDB's own read of the same bytes (Transform::read, as io::File reads a grid's transform).
openvdb::math::Transform readByOpenVdb(const openvdb::math::Transform& transform) {
    std::stringstream s;
    transform.write(s);
    openvdb::io::setCurrentVersion(s);
    openvdb::math::Transform read;
    read.read(s);
    return read;
}

TEST(VdbTypes, LinearMapsReadAsTransformReadReadsThem) {
    initOpenVdb();
    using namespace openvdb::math;
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> u(-3.0, 3.0), pos(0.1, 4.0);
    int checked = 0;
    for (int trial = 0; trial < 20; ++trial) {
        const Vec3d scale(pos(rng), pos(rng), pos(rng)), t(u(rng), u(rng), u(rng));
        Mat4d m = Mat4d::identity();
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) m(r, c) = u(rng) + (r == c ? 4.0 : 0.0);
        m.setTranslation(t);
        const std::vector<MapBase::Ptr> maps = {
            std::make_shared<AffineMap>(m),
            std::make_shared<UnitaryMap>(Vec3d(u(rng), u(rng), u(rng)).unit(), u(rng)),
            std::make_shared<ScaleMap>(scale),
            std::make_shared<UniformScaleMap>(scale.x()),
            std::make_shared<ScaleTranslateMap>(scale, t),
            std::make_shared<UniformScaleTranslateMap>(scale.x(), t),
            std::make_shared<TranslationMap>(t)};
        for (const MapBase::Ptr& map : maps) {
            Transform transform(map->copy());
            // Transform's constructor simplifies some maps: write what it holds.
            const auto [type, data] = writtenMap(transform);
            SCOPED_TRACE(type);
            const Transform want = readByOpenVdb(transform);
            const MapBase::Ptr got = readLinearMap(type, data);
            EXPECT_EQ(got->type(), want.mapType());
            EXPECT_TRUE(got->isEqual(*want.baseMap()));
            EXPECT_EQ(got->getAffineMap()->getMat4(), want.baseMap()->getAffineMap()->getMat4());  // bit for bit
            ++checked;
        }
    }
    EXPECT_EQ(checked, 140);
}

TEST(VdbTypes, EveryLinearMapTypeIsReadFromItsOwnBytes) {
    // Transform's constructor turns most maps into others; the seven types as written by the maps.
    using namespace openvdb::math;
    const Vec3d s(2.0, 3.0, 0.5), t(1.0, -2.0, 7.0);
    Mat4d m = Mat4d::identity();
    m(0, 1) = 0.25, m(2, 0) = -1.5;
    m.setTranslation(t);
    const std::vector<MapBase::Ptr> maps = {std::make_shared<AffineMap>(m),
                                            std::make_shared<UnitaryMap>(Vec3d(0, 0, 1), 0.3),
                                            std::make_shared<ScaleMap>(s),
                                            std::make_shared<UniformScaleMap>(2.0),
                                            std::make_shared<ScaleTranslateMap>(s, t),
                                            std::make_shared<UniformScaleTranslateMap>(2.0, t),
                                            std::make_shared<TranslationMap>(t)};
    for (const MapBase::Ptr& map : maps) {
        SCOPED_TRACE(map->type());
        std::ostringstream out;
        map->write(out);
        const MapBase::Ptr got = readLinearMap(map->type(), out.str());
        EXPECT_EQ(got->type(), map->type());
        EXPECT_TRUE(got->isEqual(*map));
        EXPECT_EQ(got->getAffineMap()->getMat4(), map->getAffineMap()->getMat4());
        EXPECT_THROW(readLinearMap(map->type(), out.str().substr(1)), std::invalid_argument);  // one byte short
    }
    EXPECT_THROW(readLinearMap("NonlinearFrustumMap", std::string(200, '\0')), std::invalid_argument);
    EXPECT_THROW(readLinearMap("AffineMapX", std::string(128, '\0')), std::invalid_argument);
}

TEST(VdbTypes, ASingularAffineMapIsRefusedAsOpenVdbRefusesIt) {
    initOpenVdb();
    openvdb::math::Mat4d zero = openvdb::math::Mat4d::zero();
    zero(3, 3) = 1.0;
    std::string data(reinterpret_cast<const char*>(zero.asPointer()), 128);
    EXPECT_THROW(readLinearMap("AffineMap", data), std::exception);
    std::stringstream s;
    openvdb::writeString(s, "AffineMap");
    s.write(data.data(), std::streamsize(data.size()));
    openvdb::io::setCurrentVersion(s);
    openvdb::math::Transform read;
    EXPECT_THROW(read.read(s), std::exception);
}

}  // namespace
}  // namespace vdbsplat
