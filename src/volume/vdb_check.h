// volume/vdb_check.h — a cheap structural pre-check of .vdb files before OpenVDB reads them.
// Owns: checkVdbStructure. OpenVDB 10 does not check its reads against the end of the
// file: a truncated file can make it take a string length from garbage (gigabyte
// allocations, megabyte error messages) or report "0 grids". This walks the header,
// the file metadata and every grid descriptor (all length-prefixed) and checks that
// each grid's recorded end offset lies inside the file, reading only a few hundred bytes.
#pragma once
#include <string>

namespace vdbsplat {

/// @brief Checks that @p path looks like a complete VDB file (magic, header, descriptors, grid extents).
/// @throw Error "<path>: not a VDB file …" or "<path>: truncated or corrupt VDB file (…)".
void checkVdbStructure(const std::string& path);

}  // namespace vdbsplat
