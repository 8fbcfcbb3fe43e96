// volume/grid.h — reading sparse OpenVDB grids (never densified).
// Owns: Volume (one float grid plus what the renderer needs to know about it),
// loading a named or the first scalar grid from a .vdb file (float or double;
// double is converted to a float tree of the same topology), validating its
// transform, and describing every grid of a file (`vdbsplat info`).
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

namespace vdbsplat {

struct EmissionGrid;  // volume/emission.h

/// @brief One scalar grid ready to render.
struct Volume {
    /// The values as float (a .vdb grid's tree, or an in-memory grid's); non-finite values were
    /// set to 0 (see nonFiniteCount). A Volume holds no openvdb::Grid: reading one from a .vdb
    /// file never calls into libopenvdb (volume/vdb_types.h).
    std::shared_ptr<openvdb::FloatTree> tree;
    /// The grid's index-to-world map, OpenVDB's own object (indexToWorld is its matrix).
    openvdb::math::MapBase::ConstPtr map;
    std::string file;               ///< the file it came from ("" if generated in memory)
    std::string name;               ///< the grid's name
    /// h, world units per voxel: |det A|^(1/3) for the linear part A of indexToWorld (the edge
    /// of the cube with the voxel's volume; the column length for cubic voxels).
    double voxelSize = 1.0;
    /// A is h·(rotation): cubic voxels, sphere kernels. False: anisotropic or sheared voxels,
    /// ellipsoid kernels (footprint/ellipsoid.h).
    bool isotropic = true;
    glm::dmat4 indexToWorld{1.0};   ///< affine map from index space (voxel centres at integers) to world
    glm::dmat4 worldToIndex{1.0};   ///< its inverse
    openvdb::CoordBBox indexBox;    ///< bounding box of the active voxels (inclusive)
    uint64_t activeVoxels = 0;      ///< active voxel count (active tiles counted as their voxels)
    uint64_t nonFiniteCount = 0;    ///< active voxels whose NaN/inf value was replaced by 0
    float valueMin = 0.f, valueMax = 1.f;  ///< range of finite active values
    /// An emission grid sharing this grid's kernels (volume/emission.h: attachEmission); null: none.
    std::shared_ptr<const EmissionGrid> emission;

    /// @brief World-space bounds of the active voxels' centres, widened by half a voxel.
    void worldBounds(glm::dvec3& lo, glm::dvec3& hi) const;
    /// @brief The voxel's longest axis in world units (A's largest singular value; h for cubic
    /// voxels): the spacing whose projection decides whether a voxel is a point.
    double largestAxis() const;
};

/// @brief The bounding box of the active voxels of @p tree (inclusive), as Grid::evalActiveVoxelBoundingBox.
inline openvdb::CoordBBox activeVoxelBounds(const openvdb::FloatTree& tree) {
    openvdb::CoordBBox box;
    tree.evalActiveVoxelBoundingBox(box);
    return box;
}

/// @brief Calls openvdb::initialize() once (thread-safe, idempotent). Whatever reaches OpenVDB's
/// registries calls it first (its I/O, MetaMap and Transform reading); loading a .vdb file that
/// vdbsplat's own reader covers does not.
void initOpenVdb();

/// @brief Loads grid @p gridName (or, if empty, defaultGridIndex's grid) from @p path: with
/// vdbsplat's own reader (volume/vdb_reader.h), or what it does not cover with OpenVDB's in a
/// forked child.
/// @throw Error naming the file and the problem: missing, not a VDB, truncated or corrupt,
/// no float grid, no grid of that name, an empty grid, or a transform that is not linear
/// (frustum) or is singular. Any affine map is accepted (anisotropic voxels, rotation, shear).
Volume loadVolume(const std::string& path, const std::string& gridName = "");

/// @brief Wraps an in-memory float grid (tests, generators) as a Volume, validating it as loadVolume does.
Volume makeVolume(openvdb::FloatGrid::Ptr grid, const std::string& label = "<memory>");

/// @brief True when the grids of @p a and @p b share their transform as openvdb::math::Transform's
/// operator== decides it (voxel sizes within 1e-8, then the maps: linear maps as affine
/// matrices within 1e-8 per entry), computed with OpenVDB's header-only map classes.
bool sameTransform(const Volume& a, const Volume& b);

/// @brief Empty when vdbsplat can render a grid with transform @p transform, else the reason
/// (the check loadVolume applies; `vdbsplat info` reports it).
std::string transformProblem(const openvdb::math::Transform& transform);

/// The grid rendered when no --grid is given: the float or double grid named "density" (the name
/// VFX tools give the extinction grid, wherever it stands in the file: EmberGen writes
/// flame, temperature, density), else the first float or double grid. @p names and @p scalar
/// describe the file's grids in order; returns names.size() when none is scalar.
size_t defaultGridIndex(const std::vector<std::string>& names, const std::vector<bool>& scalar);

/// @brief A human-readable description of every grid in @p path (`vdbsplat info`).
/// @throw Error as loadVolume for unreadable files.
std::string describeFile(const std::string& path);

/// @brief Writes @p grid to @p path atomically (temporary file, then rename).
/// @throw Error naming the path on failure.
void writeVolume(const std::string& path, openvdb::FloatGrid::Ptr grid);

/// @brief Writes several grids (e.g. density and temperature) to one file, as writeVolume.
void writeVolumes(const std::string& path, const std::vector<openvdb::FloatGrid::Ptr>& grids);

}  // namespace vdbsplat
