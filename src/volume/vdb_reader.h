// volume/vdb_reader.h — vdbsplat's own reader of the .vdb grids it renders, in process.
// Owns: readVdbGrid, which reads one float or double grid of an OpenVDB file (file versions
// 222-224: OpenVDB 3 to 10; blosc, zlib or raw leaf data; half-float storage; all seven
// per-node mask-compression modes; tiles at every level; the linear maps OpenVDB writes)
// straight into an openvdb::FloatTree (its name and map parsed here too: no call into
// libopenvdb, volume/vdb_types.h): nodes allocated once, leaf values decompressed into
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
#include <memory>
#include <optional>
#include <string>

namespace vdbsplat {

/// @brief A grid read by readVdbGrid, with the value statistics loadVolume needs: the tree, its
/// name and its map, made without a call into libopenvdb (volume/vdb_types.h), and the grid's
/// metadata and transform as the bytes OpenVDB would read them (toOpenVdbGrid).
struct ReadGrid {
    std::shared_ptr<openvdb::FloatTree> tree;  ///< the values as OpenVDB reads them (double: cast to float)
    std::string name;                          ///< the grid's "name" metadata, as GridBase::getName()
    openvdb::math::MapBase::Ptr map;           ///< the linear map Transform::read makes of the file's bytes
    std::string metadata;                      ///< the grid's metadata block (MetaMap::readMeta's bytes)
    std::string transform;                     ///< the transform's bytes (type name and map: Transform::read's)
    uint64_t activeVoxels = 0;     ///< active voxels, tiles counted as their voxels
    uint64_t nonFiniteCount = 0;   ///< active voxels whose NaN/inf value was replaced by 0
    float valueMin = 0.f, valueMax = 0.f;  ///< finite active value range (0, 0 if there is none)
};

/// @brief The openvdb::FloatGrid io::File::readGrid makes of the same bytes: the tree shared, the
/// metadata read by MetaMap::readMeta ("file_delayed_load" dropped, as io::File drops it) and
/// the transform by Transform::read (both in libopenvdb: for tests and tools, not the render path).
/// @throw std::exception as those readers throw.
openvdb::FloatGrid::Ptr toOpenVdbGrid(const ReadGrid& read);

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
