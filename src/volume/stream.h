// volume/stream.h — depth-ordered streaming of classified active voxels (DESIGN §5).
// Owns: VoxelStream, which walks the sparse tree (leaves, and active tiles split
// into 8³ blocks — never a dense copy), culls blocks behind the eye, outside the
// view frustum (kernel radius and prefilter as margin) or hidden behind opaque
// screen tiles, sorts the rest by their nearest distance to the eye, and releases
// voxels front to back in depth windows made of whole one-voxel slabs of radial
// distance. Memory holds only the voxels of blocks that straddle the current front.
//
// Each voxel comes out classified (σ per voxel length, colour) and in view space;
// voxels with σ = 0 are dropped here, so nothing downstream pays for them.
#pragma once
#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "camera/camera.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief One depth window of voxels, structure of arrays, in a deterministic order.
struct VoxelBatch {
    std::vector<glm::vec3> viewPos;  ///< voxel centre in view space (eye at origin, +z forward)
    std::vector<float> distance;     ///< |viewPos|, world units
    std::vector<float> sigma;        ///< extinction per voxel length (σ_k·h)
    std::vector<glm::vec3> color;    ///< emitted colour c_k
    int64_t slabBegin = 0;           ///< first slab of the window: slab = floor(distance / (h·slabThickness))
    int64_t slabEnd = 0;             ///< one past the last slab
    size_t size() const { return viewPos.size(); }
    void clear();
};

struct StreamOptions {
    double slabThickness = 1.0;  ///< slab thickness in voxels (points are summed within one slab)
    int slabsPerWindow = 8;      ///< a window is this many slabs (more when they are nearly empty)
    size_t minWindowVoxels = 1 << 15;  ///< grow the window until it holds about this many voxels
    /// Narrow the window (down to one slab) while windows hold more than this many voxels,
    /// widen it again (up to slabsPerWindow) when they hold under a quarter: the projected
    /// window is the renderer's largest buffer (two copies of ~150 B per voxel). Window
    /// boundaries are slab boundaries, so the image does not depend on this.
    size_t maxWindowVoxels = 1 << 20;
    double screenMargin = 4.0;   ///< pixels of margin around the image for frustum culling
};

class VoxelStream {
public:
    /// @brief Streams @p volume for @p camera; @p table classifies values.
    /// @throw Error when the grid is too large to stream (more than 2^32 active voxels).
    VoxelStream(const Volume& volume, const Camera& camera, const ClassificationTable& table,
                const StreamOptions& options = {});

    /// @brief Fills @p batch with the next window front to back; false when the stream is done.
    /// @param hidden optional: returns true for a block whose screen rectangle (pixels,
    /// x0, y0, x1, y1 inclusive) is entirely behind opaque pixels, so it can be skipped.
    bool next(VoxelBatch& batch, const std::function<bool(int, int, int, int)>& hidden = {});

    uint64_t culledVoxels() const { return culled_; }   ///< voxels in blocks culled so far
    uint64_t windows() const { return windows_; }        ///< windows released so far
    size_t largestWindow() const { return largest_; }    ///< most voxels in one window so far
    double slabLength() const { return slabLength_; }    ///< world length of one slab

private:
    struct Block {
        openvdb::Coord origin;          // min index corner
        int dim;                        // side in voxels (8)
        const openvdb::FloatTree::LeafNodeType* leaf;  // nullptr: an active tile block of tileValue
        float tileValue;
        float dMin, dMax;               // distance range of its voxel centres (world)
        uint32_t voxels;                // active voxels
    };
    void collectBlocks();
    bool visible(const Block& b) const;
    void screenRect(const Block& b, int& x0, int& y0, int& x1, int& y1) const;
    void extract(const Block& b, VoxelBatch& out) const;
    void adaptWindow(size_t released);  // the next window's slab count from this one's size

    const Volume& volume_;
    const Camera& camera_;
    const ClassificationTable& table_;
    StreamOptions options_;
    double slabLength_;
    std::vector<Block> blocks_;   // sorted by dMin
    size_t nextBlock_ = 0;
    VoxelBatch pending_;          // voxels of activated blocks not yet released
    int64_t nextSlab_ = 0;
    int slabsPerWindow_ = 8;      // adapted between 1 and options_.slabsPerWindow (maxWindowVoxels)
    uint64_t culled_ = 0;
    uint64_t windows_ = 0;
    size_t largest_ = 0;
};

}  // namespace vdbsplat
