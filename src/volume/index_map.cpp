// volume/index_map.cpp — index→world transforms of converted volumes (see index_map.h).
// Owns: the geometry checks and the row-vector matrix OpenVDB expects (world = [i j k 1]·M).
#include "volume/index_map.h"

#include <cmath>
#include <sstream>

#include "util/error.h"
#include "volume/raw.h"

namespace vdbsplat {

namespace {

std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

void checkAxis(const openvdb::Vec3d& axis, int a, const std::string& what) {
    if (!std::isfinite(axis[0]) || !std::isfinite(axis[1]) || !std::isfinite(axis[2]))
        throw Error(what + ": axis " + std::to_string(a) + " is not finite");
    const double length = axis.length();
    if (!(length >= kMinRawSpacing && length <= kMaxRawSpacing))
        throw Error(what + ": voxel size " + num(length) + " along axis " + std::to_string(a) +
                    " is outside [1e-4, 1e6] world units");
}

}  // namespace

openvdb::math::Transform::Ptr indexToWorld(const std::array<openvdb::Vec3d, 3>& axes, const openvdb::Vec3d& origin,
                                           const std::string& what, const std::string& originWhat) {
    for (int a = 0; a < 3; ++a) checkAxis(axes[a], a, what);
    for (int c = 0; c < 3; ++c)
        if (!(std::abs(origin[c]) <= kMaxOrigin))
            throw Error(originWhat + ": component " + num(origin[c]) + " is not finite or beyond 1e9");
    const double det = axes[0].dot(axes[1].cross(axes[2]));
    const double scale = axes[0].length() * axes[1].length() * axes[2].length();
    if (!(std::abs(det) > 1e-6 * scale)) throw Error(what + ": the axes are singular (linearly dependent)");
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) m(a, c) = axes[a][c];
    for (int c = 0; c < 3; ++c) m(3, c) = origin[c];
    return openvdb::math::Transform::createLinearTransform(m);
}

}  // namespace vdbsplat
