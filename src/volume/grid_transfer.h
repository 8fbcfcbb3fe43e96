// volume/grid_transfer.h — handing a grid read in a child process to its parent.
// Owns: the compact transfer form of a float tree (per leaf: origin, value mask, 512 floats;
// every tile above leaf level that is active or differs from the background, with its
// level; background, transform, name, grid class, and the reader's log lines), its encoder
// (run in the forked child that reads the .vdb, single-threaded: TBB is not fork-safe) and
// its decoder (run in the parent, which trusts no byte of it: every count, offset, level,
// alignment and the transform's layout are checked against the transfer's size, and the
// rebuilt tree's leaf and active voxel counts against the transfer's). The decoder also
// does what loadVolume did in a pass of its own: non-finite active values become 0
// (counted), and the finite active value range is measured, in parallel, as leaves are built.
// TransferMemory is the memfd the two processes share: the child writes it, the parent reads
// it (pread, chunk by chunk) and gives back each chunk of leaves (hole punch) once that chunk
// is in the tree, so the transfer and the tree are never both whole in memory.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace vdbsplat {

/// @brief A grid rebuilt from a transfer, with the value statistics loadVolume needs.
struct DecodedGrid {
    openvdb::FloatGrid::Ptr grid;
    uint64_t activeVoxels = 0;    ///< active voxels, tiles counted as their voxels (checked against the tree)
    uint64_t nonFiniteCount = 0;  ///< active voxels whose NaN/inf value was replaced by 0
    float valueMin = 0.f, valueMax = 0.f;  ///< finite active value range (0, 0 if there is none)
    std::string log;              ///< what the reader wrote to std::cerr in the child
};

/// @brief Writes @p grid (a float or double grid; double values are cast to float, as
/// FloatTree's converting copy does) and @p log in transfer form to file descriptor @p fd,
/// from its current position. Single-threaded; no TBB.
/// @throw Error naming @p label when the grid is of another type or a write fails.
void encodeGridTransfer(const openvdb::GridBase& grid, const std::string& log, int fd, const std::string& label);

/// @brief The transfer form of @p grid in memory (tests).
std::vector<char> encodeGridTransfer(const openvdb::GridBase& grid, const std::string& log = "");

/// @brief Rebuilds the float grid from @p size bytes at @p data. @p release, if given, is
/// called with byte ranges [begin, end) that the decoder no longer needs, in increasing order.
/// @throw Error "<label>: damaged grid transfer (…)" for anything out of bounds or inconsistent.
DecodedGrid decodeGridTransfer(const char* data, uint64_t size, const std::string& label,
                               const std::function<void(uint64_t, uint64_t)>& release = {});

/// @brief Where a decoder reads a transfer from: read(offset, bytes, to) false on failure;
/// release(begin, end) says that bytes before @p end are no longer needed.
struct TransferSource {
    uint64_t size = 0;
    std::function<bool(uint64_t, uint64_t, void*)> read;
    std::function<void(uint64_t, uint64_t)> release = [](uint64_t, uint64_t) {};
};

/// @brief An anonymous shared file (memfd) that a forked child writes a transfer into.
class TransferMemory {
public:
    /// @throw Error naming @p label when no memfd can be made.
    explicit TransferMemory(const std::string& label);
    ~TransferMemory();
    TransferMemory(const TransferMemory&) = delete;
    TransferMemory& operator=(const TransferMemory&) = delete;
    int fd() const { return fd_; }
    /// @brief Allocates @p leaves float leaves now (touching their pages), for decode() to fill:
    /// called while the child reads, it takes the parent's page faults off the critical path.
    void preallocate(uint64_t leaves);
    /// @brief Decodes what the child wrote (read with pread, chunk by chunk, each chunk
    /// punched out of the memfd once its leaves are in the tree).
    DecodedGrid decode();

private:
    int fd_ = -1;
    std::string label_;
    std::vector<std::unique_ptr<openvdb::FloatTree::LeafNodeType>> pool_;
};

}  // namespace vdbsplat
