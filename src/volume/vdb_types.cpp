// volume/vdb_types.cpp — OpenVDB's registries, answered without libopenvdb (see vdb_types.h).
#include "volume/vdb_types.h"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "volume/vdb_check.h"

namespace vdbsplat {

namespace {

/// A registered fixed-size metadata type: its name and the bytes TypedMetadata<T>::size() gives
/// (sizeof(T)); the point index types are registered with Int32Metadata's and Int64Metadata's
/// factories (openvdb::initialize, points::internal::initialize).
template <class T, class Stored = T>
std::pair<std::string_view, uint64_t> fixed() {
    return {openvdb::typeNameAsString<T>(), sizeof(Stored)};
}

}  // namespace

std::optional<uint64_t> fixedMetadataBytes(std::string_view type) {
    using namespace openvdb;
    static const std::array kFixed = {
        fixed<bool>(),           fixed<double>(),         fixed<float>(),         fixed<int32_t>(),
        fixed<int64_t>(),        fixed<Vec2i>(),          fixed<Vec2s>(),         fixed<Vec2d>(),
        fixed<Vec3i>(),          fixed<Vec3s>(),          fixed<Vec3d>(),         fixed<Vec4i>(),
        fixed<Vec4s>(),          fixed<Vec4d>(),          fixed<Mat4s>(),         fixed<Mat4d>(),
        fixed<PointIndex32, int32_t>(),     fixed<PointIndex64, int64_t>(),
        fixed<PointDataIndex32, int32_t>(), fixed<PointDataIndex64, int64_t>()};
    for (const auto& [name, bytes] : kFixed)
        if (name == type) return bytes;
    return std::nullopt;
}

namespace {
/// Every grid type's name (Grid::gridType(), from the tree's static description: no grid made).
template <class... Grids>
std::vector<std::string> gridTypeNames(openvdb::TypeList<Grids...>) {
    return {Grids::gridType()...};
}
}  // namespace

bool isRegisteredGridType(std::string_view type) {
    // openvdb::initialize() registers every grid of openvdb::GridTypes (OpenVDB 10).
    static const std::vector<std::string> kTypes = gridTypeNames(openvdb::GridTypes());
    return std::find(kTypes.begin(), kTypes.end(), type) != kTypes.end();
}

namespace {

template <class MapT>
openvdb::math::MapBase::Ptr readMap(std::string_view bytes) {
    auto map = std::make_shared<MapT>();
    MemoryStream in(bytes);
    map->read(in);
    if (!in) throw std::invalid_argument("map data ends early");
    return map;
}

}  // namespace

openvdb::math::MapBase::Ptr readLinearMap(const std::string& mapType, std::string_view bytes) {
    using namespace openvdb::math;
    const uint64_t expected = vdbMapBytes(mapType);
    if (expected == 0) throw std::invalid_argument("map type " + mapType + " is not a linear map read here");
    if (bytes.size() != expected) throw std::invalid_argument("map " + mapType + " of the wrong size");
    if (mapType == AffineMap::mapType()) return readMap<AffineMap>(bytes);
    if (mapType == UnitaryMap::mapType()) return readMap<UnitaryMap>(bytes);
    if (mapType == ScaleMap::mapType()) return readMap<ScaleMap>(bytes);
    if (mapType == UniformScaleMap::mapType()) return readMap<UniformScaleMap>(bytes);
    if (mapType == ScaleTranslateMap::mapType()) return readMap<ScaleTranslateMap>(bytes);
    if (mapType == UniformScaleTranslateMap::mapType()) return readMap<UniformScaleTranslateMap>(bytes);
    if (mapType == TranslationMap::mapType()) return readMap<TranslationMap>(bytes);
    throw std::invalid_argument("map type " + mapType + " is not a linear map read here");
}

}  // namespace vdbsplat
