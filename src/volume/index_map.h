// volume/index_map.h — the index→world transform of a converted volume (NRRD, VTI).
// Owns: building an OpenVDB linear transform from three axis vectors and an origin, and the
// checks every header's geometry must pass (finite, voxel sizes in convert's accepted range,
// origin bounded, axes not singular). Non-uniform and rotated axes are kept: converting is
// allowed, and `render` takes any of them (anisotropic voxels: ellipsoid kernels, docs/kernel.md).
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <array>
#include <string>

namespace vdbsplat {

/// Largest accepted |origin| component (world units).
inline constexpr double kMaxOrigin = 1e9;

/// @brief The transform mapping index (i,j,k) to origin + i·axes[0] + j·axes[1] + k·axes[2].
/// @param what names the file and header field in errors ("x.nrrd: space directions")
/// @throw Error naming @p what when a value is not finite, an axis length is outside
/// [kMinRawSpacing, kMaxRawSpacing], |origin| exceeds kMaxOrigin, or the axes are (nearly) singular.
openvdb::math::Transform::Ptr indexToWorld(const std::array<openvdb::Vec3d, 3>& axes, const openvdb::Vec3d& origin,
                                           const std::string& what, const std::string& originWhat);

}  // namespace vdbsplat
