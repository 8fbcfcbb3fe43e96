// volume/raw.h — raw volumes (headerless, x fastest, then y, then z) to sparse float grids.
// Owns: `vdbsplat convert`'s reader. Files are streamed (plain, or gzip through zlib's
// inflate, trailing garbage refused) a few rows at a time, never whole; uint8 and
// uint16 (little-endian) are normalised to [0,1] (÷255, ÷65535), float32 is kept
// as is. A voxel is active iff its (normalised) value is > threshold (default 0,
// so zeros are background and stay inactive); non-finite float32 values stay
// inactive and are counted.
#pragma once
#include <openvdb/openvdb.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace vdbsplat {

enum class RawType { UInt8, UInt16, Float32 };

/// Largest accepted side of a raw volume (per axis).
inline constexpr int kMaxRawDim = 65536;

/// Default bound on X*Y*Z (a few KB of gzip can expand to billions of voxels); --max-voxels
/// raises it up to kHardMaxRawVoxels.
inline constexpr uint64_t kDefaultMaxRawVoxels = uint64_t(1) << 26;
inline constexpr uint64_t kHardMaxRawVoxels = uint64_t(1) << 32;
/// Accepted voxel size range (OpenVDB refuses near-zero scales; huge ones overflow the camera).
inline constexpr double kMinRawSpacing = 1e-4;
inline constexpr double kMaxRawSpacing = 1e6;

/// @brief How to read one raw file.
struct RawSpec {
    std::array<int, 3> dims{0, 0, 0};  ///< X, Y, Z voxel counts, each in [1, kMaxRawDim]
    RawType type = RawType::UInt8;
    double spacing = 1.0;              ///< uniform voxel size (world units)
    double threshold = 0.0;            ///< active iff normalised value > threshold
    uint64_t maxVoxels = kDefaultMaxRawVoxels;  ///< X*Y*Z above this is refused before reading
};

/// @brief What a conversion found.
struct RawStats {
    uint64_t bytes = 0;       ///< bytes read (the expected size)
    uint64_t active = 0;      ///< active voxels written
    uint64_t nonFinite = 0;   ///< float32 NaN/inf values (left inactive)
};

/// @brief Bytes per voxel of @p type.
int rawTypeSize(RawType type);

/// @brief "uint8" | "uint16" | "float32" → RawType. @throw Error naming @p flag otherwise.
RawType parseRawType(std::string_view text, const std::string& flag);

/// @brief "X,Y,Z" → three integers in [1, kMaxRawDim]. @throw Error naming @p flag otherwise.
std::array<int, 3> parseDims(std::string_view text, const std::string& flag);

/// @brief "SX,SY,SZ" → the common voxel size. @throw Error naming @p flag when a value is not
/// positive, finite and in [kMinRawSpacing, kMaxRawSpacing], or when the spacing is non-uniform (the renderer needs cubic voxels).
double parseUniformSpacing(std::string_view text, const std::string& flag);

/// @brief Reads @p path (raw or gzip-compressed raw) as described by @p spec into a fog-volume
/// float grid named "density" with voxel size spec.spacing, index (0,0,0) at the world origin.
/// @param stats if not null, receives what was read
/// @throw Error "--dims: …" when X*Y*Z exceeds spec.maxVoxels (before reading); naming the file:
/// missing or unreadable, corrupt gzip data, trailing garbage after it, or a size that does not
/// match dims × type (with the expected and actual byte counts, for too short and too long files).
openvdb::FloatGrid::Ptr convertRaw(const std::string& path, const RawSpec& spec, RawStats* stats = nullptr);

}  // namespace vdbsplat
