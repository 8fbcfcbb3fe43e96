// volume/vdb_reader.h — vdbsplat's own reader of the .vdb grids it renders, in process.
// Owns: readVdbGrid, which reads one float or double grid of an OpenVDB file (file versions
// 222-224: OpenVDB 3 to 10; blosc, zlib or raw leaf data; half-float storage; all seven
// per-node mask-compression modes; tiles at every level; the linear maps OpenVDB writes)
// straight into an openvdb::FloatGrid: nodes allocated once, leaf values decompressed into
// the leaf buffers (in parallel), non-finite active values replaced by 0 and the value range
// measured as they land. Every count, size, offset and mask is checked against the bytes of
// the grid before anything is allocated or indexed from it, so a damaged file ends in one
// Error naming it. What it does not cover (older layouts, files without grid offsets,
// instanced grids, other map or value types, duplicate grid names, layouts OpenVDB reads
// in ways of its own: unsorted root nodes, tiles under children, unknown per-node flags)
// it leaves to OpenVDB's reader in a forked child (loadVolume, volume/grid.h) by returning
// nothing: correctness never depends on what it covers, only speed does.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <cstdint>
#include <optional>
#include <string>

namespace vdbsplat {

/// @brief A grid read by readVdbGrid, with the value statistics loadVolume needs.
struct ReadGrid {
    openvdb::FloatGrid::Ptr grid;  ///< the grid as OpenVDB's io::File::readGrid reads it (double: cast to float)
    uint64_t activeVoxels = 0;     ///< active voxels, tiles counted as their voxels
    uint64_t nonFiniteCount = 0;   ///< active voxels whose NaN/inf value was replaced by 0
    float valueMin = 0.f, valueMax = 0.f;  ///< finite active value range (0, 0 if there is none)
};

/// @brief Reads grid @p gridName (or, if empty, defaultGridIndex's grid) of the .vdb file
/// image @p data of @p size bytes; @p label names it in errors.
/// @return nothing when this reader leaves the file to OpenVDB (the reason in @p unsupported,
/// if given): a layout it does not cover, or a grid it cannot choose (no such name, not scalar:
/// OpenVDB's path then words the error).
/// @throw Error "<label>: truncated or corrupt VDB file (…)" for anything out of bounds,
/// inconsistent or undecodable.
std::optional<ReadGrid> readVdbGrid(const char* data, uint64_t size, const std::string& label,
                                    const std::string& gridName, std::string* unsupported = nullptr);

/// @brief readVdbGrid on the file @p path (mapped read-only).
/// @throw Error naming @p path when it cannot be opened or mapped, or as above.
std::optional<ReadGrid> readVdbGrid(const std::string& path, const std::string& gridName,
                                    std::string* unsupported = nullptr);

}  // namespace vdbsplat
