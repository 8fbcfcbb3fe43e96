// volume/nrrd.h — NRRD volumes (Teem's format: `.nrrd` with attached data, `.nhdr` + a detached
// data file) to sparse float grids.
// Owns: parsing the NRRD header (the fields convert needs: dimension 3, type, sizes, endian,
// encoding raw|gzip, data file, byte skip, space / space dimension, space directions or
// spacings, space origin; other fields and key/value pairs are read and ignored), and its
// geometry as the grid's transform. The voxels go through readVoxels (volume/raw.h), so a
// NRRD converts to exactly the grid the same data gives as raw.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <string>

#include "volume/raw.h"

namespace vdbsplat {

/// Bound on a NRRD header (bytes): real headers are a few hundred bytes.
inline constexpr size_t kMaxNrrdHeaderBytes = size_t(1) << 20;

/// @brief What a NRRD header says.
struct NrrdHeader {
    VoxelLayout layout;
    VoxelSource source;                      ///< the data: this file after the header, or the detached file
    std::array<openvdb::Vec3d, 3> axes{};    ///< world step per index axis (space directions or spacings)
    openvdb::Vec3d origin{0.0, 0.0, 0.0};    ///< world position of voxel (0,0,0) (space origin)
    openvdb::math::Transform::Ptr transform; ///< index→world from axes and origin (checked)
};

/// @brief Parses the header of @p path (nothing of the data is read).
/// @throw Error "<path>: <field>: …" for a missing, repeated, malformed, inconsistent or
/// unsupported field; sizes whose product exceeds @p maxVoxels are refused here.
NrrdHeader readNrrdHeader(const std::string& path, uint64_t maxVoxels = kDefaultMaxRawVoxels);

/// @brief Converts @p path into a fog-volume float grid named "density" whose transform keeps the
/// header's spacing, directions and origin.
/// @throw Error naming the file and field (header errors, size mismatch, corrupt gzip, geometry).
openvdb::FloatGrid::Ptr convertNrrd(const std::string& path, const ConvertOptions& options, RawStats* stats = nullptr);

}  // namespace vdbsplat
