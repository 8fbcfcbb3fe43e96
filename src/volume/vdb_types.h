// volume/vdb_types.h — what OpenVDB's registries say about a .vdb file's type names, answered
// without libopenvdb.
// Owns: the sizes of the fixed-size metadata types and the grid types that openvdb::initialize()
// registers (OpenVDB 10), and the linear maps read from their stream bytes. vdbsplat's own reader (volume/vdb_reader.h) and the structural pre-check
// (volume/vdb_check.h) ask these instead of OpenVDB's registries, so that rendering a .vdb never
// calls into libopenvdb.so: the executable loads that library lazily (CMake
// VDBSPLAT_LAZY_OPENVDB), and its ~52 000 symbolic relocations cost ~45 ms per process when it is
// loaded (docs/performance.md, session 19). tests/volume/test_vdb_types.cpp checks every answer
// against OpenVDB's own registries.
#pragma once
#include <openvdb/math/Maps.h>

#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <streambuf>
#include <string_view>

namespace vdbsplat {

/// @brief A read-only std::istream over bytes in memory (OpenVDB's readers take streams).
class MemoryStream : private std::streambuf, public std::istream {
public:
    explicit MemoryStream(std::string_view bytes) : std::istream(static_cast<std::streambuf*>(this)) {
        char* p = const_cast<char*>(bytes.data());  // never written: a get area only
        setg(p, p, p + bytes.size());
    }
};

/// @brief Bytes OpenVDB reads for a metadata value of registered fixed-size type @p type
/// (`createMetadata(type)->size()`); std::nullopt for "string", unregistered types and
/// "__delayedload" (vdbsplat unregisters it: initOpenVdb), whose declared size is what is read.
std::optional<uint64_t> fixedMetadataBytes(std::string_view type);

/// @brief True when openvdb::GridBase::isRegistered(@p type) holds after openvdb::initialize().
bool isRegisteredGridType(std::string_view type);

/// @brief The linear map of type @p mapType (AffineMap, UnitaryMap, ScaleMap, UniformScaleMap,
/// ScaleTranslateMap, UniformScaleTranslateMap, TranslationMap) read from its stream bytes @p bytes
/// (what follows the type name, as Transform::write puts it; vdbMapBytes of them) by OpenVDB's own
/// map class, whose code is all in its header: what Transform::read makes of the same bytes.
/// @throw std::exception as OpenVDB's map read throws (a nearly singular affine matrix), or
/// std::invalid_argument for another type or a size other than vdbMapBytes(@p mapType).
openvdb::math::MapBase::Ptr readLinearMap(const std::string& mapType, std::string_view bytes);

}  // namespace vdbsplat
