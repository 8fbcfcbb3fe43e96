// volume/vti.h — VTK XML ImageData (.vti) volumes to sparse float grids.
// Owns: the .vti container: the XML (pugixml; the raw appended block after `_` is never
// parsed as XML), VTKFile's byte_order / header_type / compressor, ImageData's WholeExtent,
// Origin, Spacing and Direction, the one Piece, the PointData array (by --array name, the
// active Scalars, or the first), and its data in every VTK form: ascii, inline base64
// ("binary"), appended raw or base64, each with or without zlib blocks, UInt32 or UInt64
// headers. Decoded bytes go through DensityBuilder (volume/raw.h), so a .vti converts to
// exactly the grid the same data gives as raw.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <string>

#include "volume/raw.h"

namespace vdbsplat {

/// Bound on the XML part of a .vti (bytes): inline ascii/base64 data lives in it.
inline constexpr uint64_t kMaxVtiXmlBytes = uint64_t(1) << 30;

/// @brief Converts @p path into a fog-volume float grid named "density"; voxel (0,0,0) is the
/// first point of WholeExtent, the transform is Origin + Direction·diag(Spacing)·(extent index).
/// @throw Error "<path>: <element or attribute>: …" for malformed XML, a missing, inconsistent or
/// unsupported field, data whose size does not match WholeExtent, a zlib block that lies about
/// its size, a singular transform; sizes are checked against options.maxVoxels before reading.
openvdb::FloatGrid::Ptr convertVti(const std::string& path, const ConvertOptions& options, RawStats* stats = nullptr);

}  // namespace vdbsplat
