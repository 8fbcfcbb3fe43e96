// volume/raw.h — raw volumes (headerless, x fastest, then y, then z) to sparse float grids.
// Owns: `vdbsplat convert`'s raw reader and the voxel path every convert format shares
// (NRRD and VTI feed their bytes through DensityBuilder and readVoxels): files are streamed
// (plain, or gzip through zlib's inflate, trailing garbage refused) a few rows at a time,
// never whole; uint8, uint16 and int16 are normalised (÷255, ÷65535, ÷32767), float32 and
// float64 are kept as is. A voxel is active iff its (normalised) value is > threshold
// (default 0, so zeros are background and stay inactive); non-finite values (and float64
// values beyond float32's range) stay inactive and are counted.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace vdbsplat {

enum class RawType { UInt8, Int16, UInt16, Float32, Float64 };

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
    std::array<double, 3> spacing{1.0, 1.0, 1.0};  ///< voxel size along x, y, z (world units)
    double threshold = 0.0;            ///< active iff normalised value > threshold
    uint64_t maxVoxels = kDefaultMaxRawVoxels;  ///< X*Y*Z above this is refused before reading
};

/// @brief What every convert format takes besides the file (NRRD and VTI headers give the rest).
struct ConvertOptions {
    double threshold = 0.0;                     ///< active iff normalised value > threshold
    uint64_t maxVoxels = kDefaultMaxRawVoxels;  ///< X*Y*Z above this is refused before reading
    std::string array;                          ///< VTI only: the DataArray to read ("" = the active scalars, or the first)
};

/// @brief What a conversion found.
struct RawStats {
    uint64_t voxels = 0;      ///< X*Y*Z of the volume
    uint64_t bytes = 0;       ///< bytes read (the expected size)
    uint64_t active = 0;      ///< active voxels written
    uint64_t nonFinite = 0;   ///< float32 NaN/inf values (left inactive)
};

/// @brief Bytes per voxel of @p type.
int rawTypeSize(RawType type);

/// @brief Its name as --type spells it ("uint8", "int16", …).
const char* rawTypeName(RawType type);

/// @brief "uint8" | "int16" | "uint16" | "float32" | "float64" → RawType. @throw Error naming @p flag otherwise.
RawType parseRawType(std::string_view text, const std::string& flag);

/// @brief "X,Y,Z" → three integers in [1, kMaxRawDim]. @throw Error naming @p flag otherwise.
std::array<int, 3> parseDims(std::string_view text, const std::string& flag);

/// @brief "SX,SY,SZ" → the voxel size along x, y and z (any three, e.g. 1,1,2.5 for thick
/// slices: the renderer takes anisotropic voxels, docs/kernel.md). @throw Error naming @p flag
/// when a value is not positive, finite and in [kMinRawSpacing, kMaxRawSpacing].
std::array<double, 3> parseSpacing(std::string_view text, const std::string& flag);

/// @brief The linear transform of voxel size @p spacing, index (0,0,0) at the world origin: a
/// uniform scale map when the three are equal, else a scale map with one size per axis.
openvdb::math::Transform::Ptr spacingTransform(const std::array<double, 3>& spacing);

/// @brief How the voxels of a volume are laid out, whatever the file format around them.
struct VoxelLayout {
    std::array<int, 3> dims{0, 0, 0};  ///< X, Y, Z voxel counts (x fastest, then y, then z)
    RawType type = RawType::UInt8;
    bool bigEndian = false;
};

/// @brief X*Y*Z of @p dims.
uint64_t voxelCount(const std::array<int, 3>& dims);

/// @brief Refuses @p dims whose X*Y*Z exceeds @p maxVoxels, before anything is read.
/// @throw Error starting with @p field (e.g. "--dims", "x.nrrd: sizes") and naming --max-voxels.
void checkVoxelLimit(const std::array<int, 3>& dims, uint64_t maxVoxels, const std::string& field);

/// @brief Builds the density grid from voxels given in file order (x fastest): decoding,
/// normalisation and the threshold rule of every convert format live here and only here.
class DensityBuilder {
public:
    /// @param transform the index→world map of the grid (index (0,0,0) is the first voxel)
    DensityBuilder(const VoxelLayout& layout, double threshold, openvdb::math::Transform::Ptr transform);

    /// @brief Adds the next @p n bytes of voxel data (a voxel may be split across calls);
    /// bytes past the last voxel are counted in bytes() but ignored.
    void addBytes(const unsigned char* data, size_t n);
    /// @brief Bytes given so far, and bytes the layout needs.
    uint64_t bytes() const { return bytes_; }
    uint64_t expectedBytes() const { return total_ * uint64_t(rawTypeSize(layout_.type)); }
    const RawStats& stats() const { return stats_; }
    openvdb::FloatGrid::Ptr grid() const { return grid_; }

private:
    void addVoxel(const unsigned char* bytes);

    VoxelLayout layout_;
    double threshold_;
    openvdb::FloatGrid::Ptr grid_;
    openvdb::FloatGrid::Accessor acc_;
    RawStats stats_;
    uint64_t total_ = 0, next_ = 0, bytes_ = 0;
    openvdb::Coord at_{0, 0, 0};
    unsigned char pending_[8] = {};
    int pendingBytes_ = 0;
};

/// @brief Where a volume's voxels lie in a file.
struct VoxelSource {
    enum class Encoding { Detect, Raw, Gzip };  ///< Detect: gzip iff the data starts with gzip's magic
    std::string path;
    std::string label;       ///< how errors name the data ("" = path)
    uint64_t offset = 0;     ///< file offset where the (plain or gzip) data stream starts
    uint64_t skip = 0;       ///< bytes of the decoded stream skipped before the first voxel
    bool atEnd = false;      ///< plain data only: the voxels are the file's last bytes
    Encoding encoding = Encoding::Detect;
    std::string sizeField = "--dims";  ///< what size errors name ("--dims", "sizes")
};

/// @brief Streams the voxels of @p source through a DensityBuilder, checking the exact size
/// (plain files before reading, gzip by counting, both too short and too long).
/// @throw Error naming the file: missing, unreadable, corrupt gzip, trailing garbage, size mismatch.
openvdb::FloatGrid::Ptr readVoxels(const VoxelSource& source, const VoxelLayout& layout, double threshold,
                                   openvdb::math::Transform::Ptr transform, RawStats* stats = nullptr);

/// @brief Reads @p path (raw or gzip-compressed raw) as described by @p spec into a fog-volume
/// float grid named "density" with voxel size spec.spacing (spacingTransform), index (0,0,0) at the world origin.
/// @param stats if not null, receives what was read
/// @throw Error "--dims: …" when X*Y*Z exceeds spec.maxVoxels (before reading); naming the file:
/// missing or unreadable, corrupt gzip data, trailing garbage after it, or a size that does not
/// match dims × type (with the expected and actual byte counts, for too short and too long files).
openvdb::FloatGrid::Ptr convertRaw(const std::string& path, const RawSpec& spec, RawStats* stats = nullptr);

}  // namespace vdbsplat
