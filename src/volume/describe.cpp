// volume/describe.cpp — the text of `vdbsplat info` (describeFile, declared in grid.h).
// Owns: a description of every grid of a .vdb file — name, value type, class, active
// voxel count, index and world bounding boxes, voxel size, the index→world matrix,
// and the value range of float/double grids. Works for any grid type the library
// registers (vector, int, bool, points…) and for empty grids; never renders. Everything
// taken from the file is escaped (printable) before it reaches the terminal.
#include <openvdb/io/File.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include "util/error.h"
#include "volume/grid.h"
#include "volume/vdb_check.h"

namespace vdbsplat {

namespace {

/// Text from the file, safe to print on a terminal: control characters (C0, DEL, and the
/// C1 range U+0080–U+009F, which includes CSI) and bytes that are not valid UTF-8 are
/// written as \xHH, so a grid name cannot send escape sequences or break the line layout.
std::string printable(const std::string& text) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    const auto escape = [&](unsigned char u) { out += std::string("\\x") + hex[u >> 4] + hex[u & 15]; };
    for (size_t i = 0; i < text.size();) {
        const auto u = static_cast<unsigned char>(text[i]);
        if (u < 0x80) {
            if (u < 0x20 || u == 0x7f || u == '\\') escape(u); else out += char(u);
            ++i;
            continue;
        }
        const int n = u >= 0xf0 && u < 0xf5 ? 4 : u >= 0xe0 ? 3 : u >= 0xc2 && u < 0xe0 ? 2 : 0;
        bool valid = n > 0 && i + n <= text.size();
        for (int k = 1; valid && k < n; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
        if (valid && n == 2 && u == 0xc2 && static_cast<unsigned char>(text[i + 1]) < 0xa0) valid = false;  // C1
        if (!valid) {
            escape(u);
            ++i;
            continue;
        }
        out.append(text, i, size_t(n));
        i += size_t(n);
    }
    return out;
}

std::string vec3(const openvdb::Vec3d& v) {
    std::ostringstream s;
    s << std::setprecision(9) << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return s.str();
}

std::string coord(const openvdb::Coord& c) {
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")";
}

/// World box of the voxels' extents (centres ± half a voxel) through any map.
std::string worldBox(const openvdb::math::Transform& xform, const openvdb::CoordBBox& box) {
    openvdb::Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int corner = 0; corner < 8; ++corner) {
        const openvdb::Vec3d p(corner & 1 ? box.max().x() + 0.5 : box.min().x() - 0.5,
                               corner & 2 ? box.max().y() + 0.5 : box.min().y() - 0.5,
                               corner & 4 ? box.max().z() + 0.5 : box.min().z() - 0.5);
        const openvdb::Vec3d w = xform.indexToWorld(p);
        lo = openvdb::math::minComponent(lo, w);
        hi = openvdb::math::maxComponent(hi, w);
    }
    return vec3(lo) + " .. " + vec3(hi);
}

std::string matrixText(const openvdb::math::Transform& xform) {
    if (!xform.isLinear()) return "    (" + printable(xform.mapType()) + ": not linear, no matrix)\n";
    openvdb::Mat4d m;
    try {  // OpenVDB inverts the matrix as it builds the affine map: a singular one throws
        m = xform.baseMap()->getAffineMap()->getMat4();
    } catch (const std::exception& e) {
        return "    (singular or invalid: " + printable(e.what()) + ")\n";
    }
    std::ostringstream s;
    s << std::setprecision(9);
    for (int r = 0; r < 4; ++r)
        s << "    [" << m(r, 0) << ", " << m(r, 1) << ", " << m(r, 2) << ", " << m(r, 3) << "]\n";
    return s.str();
}

/// Range of the active values of a float or double grid ("" for other types).
template <typename GridT>
std::string valueRange(const openvdb::GridBase& base) {
    const auto* grid = dynamic_cast<const GridT*>(&base);
    if (!grid) return "";
    double lo = std::numeric_limits<double>::max(), hi = -lo;
    uint64_t nonFinite = 0;
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        const double v = double(*it);
        if (!std::isfinite(v)) { ++nonFinite; continue; }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    std::ostringstream s;
    s << std::setprecision(9);
    if (lo <= hi) s << "  value range:   [" << lo << ", " << hi << "]\n";
    if (nonFinite) s << "  non-finite:    " << nonFinite << " active values (tiles counted once)\n";
    return s.str();
}

bool isScalar(const openvdb::GridBase& g) { return g.valueType() == "float" || g.valueType() == "double"; }

/// Names that VFX tools give the grids that drive emission (Houdini, EmberGen, Blender).
bool soundsEmissive(std::string name) {
    for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
    for (const char* word : {"temperature", "temp", "flame", "fire", "heat", "emission", "fuel"})
        if (name.find(word) != std::string::npos) return true;
    return false;
}

/// What grid @p i of @p grids can be used for: density (--grid), emission (--emission, with
/// every density grid of the same transform), or nothing and why.
std::string usage(const openvdb::GridPtrVec& grids, size_t i) {
    const openvdb::GridBase& g = *grids[i];
    if (!isScalar(g)) return "not renderable (" + printable(g.valueType()) + " values; vdbsplat renders float and double grids)";
    if (g.activeVoxelCount() == 0) return "not renderable (no active voxels)";
    const std::string problem = transformProblem(g.transform());
    if (!problem.empty()) return "not renderable (" + printable(problem) + ")";
    std::vector<std::string> names;
    std::vector<bool> scalar;
    for (const auto& grid : grids) names.push_back(grid->getName()), scalar.push_back(isScalar(*grid));
    const size_t fallback = defaultGridIndex(names, scalar);
    std::string out = "density (--grid " + printable(g.getName()) + (i == fallback ? ", the default)" : ")");
    std::string partners;
    for (size_t k = 0; k < grids.size(); ++k)
        if (k != i && isScalar(*grids[k]) && grids[k]->transform() == g.transform() && grids[k]->activeVoxelCount() > 0)
            partners += std::string(partners.empty() ? "" : ", ") + "'" + printable(grids[k]->getName()) + "'";
    if (!partners.empty())
        out += "; emission (--emission " + printable(g.getName()) + ") with density grid " + partners +
               (soundsEmissive(g.getName()) ? " (its name suggests emission)" : "");
    return out;
}

std::string describeGrid(const openvdb::GridBase& grid, size_t index) {
    std::ostringstream s;
    const auto& xform = grid.transform();
    const uint64_t active = grid.activeVoxelCount();
    s << "grid " << index << ": '" << printable(grid.getName()) << "'\n";
    s << "  value type:    " << printable(grid.valueType()) << "\n";
    s << "  class:         " << printable(openvdb::GridBase::gridClassToString(grid.getGridClass())) << "\n";
    s << "  active voxels: " << active << "\n";
    if (active == 0) {
        s << "  index bbox:    empty\n  world bbox:    empty\n";
    } else {
        const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
        s << "  index bbox:    " << coord(box.min()) << " .. " << coord(box.max()) << " (inclusive, "
          << box.dim().x() << " x " << box.dim().y() << " x " << box.dim().z() << ")\n";
        s << "  world bbox:    " << worldBox(xform, box) << " (voxel extents)\n";
    }
    s << "  voxel size:    " << vec3(xform.voxelSize()) << "\n";
    s << "  transform:     " << printable(xform.mapType()) << ", index -> world (row vector times matrix):\n" << matrixText(xform);
    s << valueRange<openvdb::FloatGrid>(grid) << valueRange<openvdb::DoubleGrid>(grid);
    return s.str();
}

/// Every grid of @p path, and the file's version.
openvdb::GridPtrVecPtr readAllGrids(const std::string& path, std::string& version) {
    openvdb::io::File file(path);
    openVdbFile(file, path);
    openvdb::GridPtrVecPtr grids;
    try {
        version = file.version();
        grids = file.getGrids();
    } catch (const std::exception& e) {
        throw Error(path + ": corrupt or truncated VDB file (" + std::string(e.what()) + ")");
    }
    file.close();
    return grids;
}

}  // namespace

std::string describeFile(const std::string& path) {
    initOpenVdb();
    OpenVdbLogCapture log;  // OpenVDB's warnings about a bad file stay out of its one-line error
    std::string version;
    readInChildProcess(path, [&] { readAllGrids(path, version); });  // a crash there is an Error here
    const openvdb::GridPtrVecPtr grids = readAllGrids(path, version);
    std::ostringstream s;
    s << printable(path) << ": VDB file version " << printable(version) << ", " << grids->size() << " grid" << (grids->size() == 1 ? "" : "s")
      << "\n";
    try {
        for (size_t i = 0; i < grids->size(); ++i)
            s << describeGrid(*(*grids)[i], i) << "  use:           " << usage(*grids, i) << "\n";
    } catch (const std::exception& e) {  // OpenVDB's own exceptions from a grid it read
        throw Error(path + ": corrupt VDB file (" + std::string(e.what()) + ")");
    }
    log.keep();  // OpenVDB's warnings only beside a description, never beside the error
    return s.str();
}

}  // namespace vdbsplat
