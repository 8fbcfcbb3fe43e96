// volume/grid.cpp — loading and validating sparse grids (see grid.h).
#include "volume/grid.h"

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/File.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <iostream>
#include <mutex>
#include <unistd.h>

#include "footprint/ellipsoid.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "volume/grid_transfer.h"
#include "volume/vdb_check.h"
#include "volume/vdb_reader.h"

namespace vdbsplat {

namespace {

bool isScalarType(const std::string& type) { return type == "float" || type == "double"; }

/// The leaves a grid of @p meta's value type held when written (from the stats metadata that
/// io::File::write adds: file_mem_bytes); 0 when unknown.
uint64_t estimatedLeaves(const openvdb::GridBase& meta) {
    const auto bytes = meta.getMetadata<openvdb::Int64Metadata>("file_mem_bytes");
    if (!bytes || bytes->value() <= 0) return 0;
    const uint64_t perLeaf = meta.valueType() == "double"
                                 ? sizeof(openvdb::DoubleTree::LeafNodeType) + 512 * sizeof(double)
                                 : sizeof(openvdb::FloatTree::LeafNodeType) + 512 * sizeof(float);
    return uint64_t(bytes->value()) / perLeaf;
}

/// Opens @p path and reads the grid to render: @p gridName, or defaultGridIndex's.
/// @p hint, if given, gets the grid's estimated leaf count before its values are read.
openvdb::GridBase::Ptr readGridToRender(const std::string& path, const std::string& gridName,
                                        const std::function<void(uint64_t)>& hint = {}) {
    openvdb::io::File file(path);
    openVdbFile(file, path);
    openvdb::GridBase::Ptr base;
    try {
        const auto metas = file.readAllGridMetadata();
        std::string chosen;
        std::vector<std::string> names;
        std::vector<bool> scalar;
        for (const auto& meta : *metas) names.push_back(meta->getName()), scalar.push_back(isScalarType(meta->valueType()));
        const size_t fallback = defaultGridIndex(names, scalar);
        for (size_t k = 0; k < metas->size(); ++k) {
            const auto& meta = (*metas)[k];
            if (!gridName.empty() ? meta->getName() == gridName : k == fallback) {
                if (!isScalarType(meta->valueType()))
                    throw Error(path + ": grid '" + gridName + "' holds " + meta->valueType() +
                                " values; only float and double grids can be rendered");
                chosen = meta->getName();
                if (hint) hint(estimatedLeaves(*meta));
                break;
            }
        }
        if (chosen.empty() && !gridName.empty()) throw Error(path + ": no grid named '" + gridName + "'");
        if (chosen.empty() && metas->empty()) throw Error(path + ": file holds no grids");
        if (chosen.empty()) throw Error(path + ": no float or double grid in the file");
        base = file.readGrid(chosen);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path + ": corrupt or truncated VDB file (" + std::string(e.what()) + ")");
    }
    file.close();
    return base;
}

/// The index→world matrix of a linear (affine) transform: any rotation, scale per axis, shear
/// and translation (the kernels are then ellipsoids, footprint/ellipsoid.h). @p voxelSize gets
/// h = |det A|^(1/3), the edge of the cube of the voxel's volume: the energy rule's M = h³ is
/// the kernel's world volume, and a transfer function's "per voxel" extinction is per h.
/// Refuses frustum (non-linear) maps and singular or non-finite matrices.
glm::dmat4 linearAffineMap(const openvdb::math::MapBase& map, const std::string& label, double& voxelSize,
                           bool& isotropic) {
    if (!map.isLinear()) throw Error(label + ": transform is not linear (frustum maps are not supported)");
    openvdb::Mat4d m;
    try {  // OpenVDB inverts the matrix as it builds the affine map: a singular one throws
        m = map.getAffineMap()->getMat4();
    } catch (const std::exception& e) {
        throw Error(label + ": transform is singular or invalid (" + std::string(e.what()) + ")");
    }
    glm::dmat4 out(1.0);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[c][r] = m(c, r);  // OpenVDB is row-vector: world = [i j k 1]·m
    const glm::dvec3 a0(out[0]), a1(out[1]), a2(out[2]);
    const double h0 = glm::length(a0), h1 = glm::length(a1), h2 = glm::length(a2);
    const double det = glm::determinant(glm::dmat3(out));
    if (!std::isfinite(h0 + h1 + h2 + det) || !std::isfinite(out[3].x + out[3].y + out[3].z))
        throw Error(label + ": transform has a non-finite entry");
    if (!(h0 > 0.0 && h1 > 0.0 && h2 > 0.0)) throw Error(label + ": transform has a zero voxel size");
    // |det| against the product of the column lengths: 1 for orthogonal axes, 0 for a flat map.
    if (!(std::abs(det) > 1e-9 * h0 * h1 * h2))
        throw Error(label + ": transform is singular (its voxel axes are linearly dependent)");
    voxelSize = std::cbrt(std::abs(det));
    const double tol = 1e-6 * h0;
    isotropic = std::abs(h1 - h0) <= tol && std::abs(h2 - h0) <= tol && std::abs(glm::dot(a0, a1)) <= tol * h0 &&
                std::abs(glm::dot(a0, a2)) <= tol * h0 && std::abs(glm::dot(a1, a2)) <= tol * h0;
    if (isotropic) voxelSize = h0;  // a rotation of cubes: exactly the column length, as before
    return out;
}

glm::dmat4 linearAffineMap(const openvdb::math::Transform& transform, const std::string& label, double& voxelSize,
                           bool& isotropic) {
    return linearAffineMap(*transform.baseMap(), label, voxelSize, isotropic);
}

/// Replaces non-finite active values by 0 and measures the finite value range.
void sanitizeValues(Volume& v) {
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    uint64_t bad = 0;
    for (auto it = v.tree->beginValueOn(); it; ++it) {
        const float x = *it;
        if (!std::isfinite(x)) {
            it.setValue(0.0f);
            bad += it.getVoxelCount();
            continue;
        }
        lo = std::min(lo, x);
        hi = std::max(hi, x);
    }
    v.nonFiniteCount = bad;
    if (lo > hi) lo = hi = 0.0f;  // every value was non-finite
    v.valueMin = lo;
    v.valueMax = hi;
}

}  // namespace

size_t defaultGridIndex(const std::vector<std::string>& names, const std::vector<bool>& scalar) {
    size_t first = names.size();
    for (size_t k = 0; k < names.size(); ++k) {
        if (!scalar[k]) continue;
        if (names[k] == "density") return k;
        if (first == names.size()) first = k;
    }
    return first;
}


bool sameTransform(const Volume& a, const Volume& b) {
    // openvdb::math::Transform::operator== (math/Transform.cc), on the maps themselves.
    const openvdb::math::MapBase &p = *a.map, &q = *b.map;
    if (!p.voxelSize().eq(q.voxelSize())) return false;
    if (p.type() == q.type()) return p.isEqual(q);
    if (p.isLinear() && q.isLinear()) return *p.getAffineMap() == *q.getAffineMap();
    return p.isEqual(q);
}

std::string transformProblem(const openvdb::math::Transform& transform) {
    try {
        double voxelSize = 0.0;
        bool isotropic = true;
        linearAffineMap(transform, "transform", voxelSize, isotropic);
        return "";
    } catch (const Error& e) {
        const std::string what = e.what();
        return what.rfind("transform: ", 0) == 0 ? what.substr(11) : what;
    }
}

void initOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] {
        openvdb::initialize();
        // vdbsplat never delay-loads, and DelayedLoadMetadata::readValue sizes its arrays from
        // counts inside the value, not from the size the file declares (a damaged count
        // allocates gigabytes). Unregistered, "__delayedload" items are read as unknown
        // metadata of their declared size, which checkVdbStructure bounds by the file.
        openvdb::Metadata::unregisterType(openvdb::io::DelayedLoadMetadata::staticTypeName());
    });
}

double Volume::largestAxis() const {
    return isotropic ? voxelSize : singularValues(glm::dmat3(indexToWorld)).x;
}

void Volume::worldBounds(glm::dvec3& lo, glm::dvec3& hi) const {
    lo = glm::dvec3(std::numeric_limits<double>::max());
    hi = -lo;
    const openvdb::Coord a = indexBox.min(), b = indexBox.max();
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec4 p((corner & 1 ? b.x() + 0.5 : a.x() - 0.5), (corner & 2 ? b.y() + 0.5 : a.y() - 0.5),
                           (corner & 4 ? b.z() + 0.5 : a.z() - 0.5), 1.0);
        const glm::dvec3 w(indexToWorld * p);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
}

namespace {

std::string gridLabel(const std::string& label, const std::string& name) {
    return label + (name.empty() ? "" : " grid '" + name + "'");
}

/// A Volume around @p tree, named @p name, with index-to-world map @p map, of @p activeVoxels
/// active voxels, values not yet sanitized.
Volume wrapTree(std::shared_ptr<openvdb::FloatTree> tree, std::string name, openvdb::math::MapBase::ConstPtr map,
                const std::string& label, uint64_t activeVoxels) {
    Volume v;
    v.tree = std::move(tree);
    v.name = std::move(name);
    v.map = std::move(map);
    const std::string where = gridLabel(label, v.name);
    v.indexToWorld = linearAffineMap(*v.map, where, v.voxelSize, v.isotropic);
    v.worldToIndex = glm::inverse(v.indexToWorld);
    v.activeVoxels = activeVoxels;
    if (v.activeVoxels == 0) throw Error(where + ": grid has no active voxels");
    v.indexBox = activeVoxelBounds(*v.tree);
    return v;
}

/// wrapTree of an in-memory (or OpenVDB-read) grid: its tree, name and map.
Volume wrapGrid(const openvdb::FloatGrid::Ptr& grid, const std::string& label, uint64_t activeVoxels) {
    return wrapTree(grid->treePtr(), grid->getName(), grid->transform().baseMap(), label, activeVoxels);
}

}  // namespace

Volume makeVolume(openvdb::FloatGrid::Ptr grid, const std::string& label) {
    const uint64_t active = grid->activeVoxelCount();
    Volume v = wrapGrid(grid, label, active);
    sanitizeValues(v);
    return v;
}

namespace {
/// Prefix of the child's message when its read succeeded but the hand-over failed.
constexpr const char* kHandOverFailed = "[hand-over] ";

/// The fallback when the memfd hand-over fails (RLIMIT_FSIZE applies to memfds): a plain read
/// here, after the child has shown that OpenVDB reads this file without crashing.
Volume loadDirectly(const std::string& path, const std::string& gridName) {
    OpenVdbLogCapture log;
    const openvdb::GridBase::Ptr base = readGridToRender(path, gridName);
    log.keep();
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) {
        const auto d = openvdb::gridPtrCast<openvdb::DoubleGrid>(base);
        grid = openvdb::FloatGrid::create(std::make_shared<openvdb::FloatTree>(d->tree()));  // value-converting copy
        grid->setTransform(d->transform().copy());
        grid->setName(d->getName());
        grid->setGridClass(d->getGridClass());
    }
    Volume v = makeVolume(grid, path);
    v.file = path;
    return v;
}
}  // namespace

namespace {
// OpenVDB's reader, for what readVdbGrid leaves to it: the grid is read once, in a forked
// child (OpenVDB's reader can crash on damaged data: there that is a one-line Error here),
// which hands it over as a float tree through a memfd (volume/grid_transfer.h); the parent
// allocates the leaves meanwhile, then rebuilds the tree, checking every byte, and sanitizes
// its values as it goes. OpenVDB's log lines are captured in the child and written here only
// when the read succeeded, as before; this process's stderr is never redirected.
Volume loadInChild(const std::string& path, const std::string& gridName) {
    initOpenVdb();  // OpenVDB's reader (in the child) and the hand-over's transform (here)
    TransferMemory transfer(path);
    ChildRead child(path, [&](const std::function<void(uint64_t)>& hint) {
        OpenVdbLogCapture log;
        const openvdb::GridBase::Ptr base = readGridToRender(path, gridName, hint);
        double voxelSize = 0.0;  // refuse what the parent would refuse, before handing it over
        bool isotropic = true;
        linearAffineMap(base->transform(), gridLabel(path, base->getName()), voxelSize, isotropic);
        try {
            encodeGridTransfer(*base, log.held(), transfer.fd(), path);
        } catch (const Error& e) {  // the read worked; only the hand-over did not (e.g. ulimit -f)
            throw Error(kHandOverFailed + std::string(e.what()));
        }
    });
    // While the child reads, allocate the leaves it estimates (their page faults are most of
    // what building a tree costs), at most one per 64 bytes of file: each leaf's value mask
    // is stored there uncompressed.
    if (const std::optional<uint64_t> leaves = child.hint()) {
        std::error_code ec;
        const uint64_t fileBytes = std::filesystem::file_size(path, ec);
        transfer.preallocate(std::min(*leaves, ec ? 0 : fileBytes / 64));
    }
    try {
        child.succeeded();
    } catch (const Error& e) {
        if (std::string(e.what()).rfind(kHandOverFailed, 0) != 0) throw;
        return loadDirectly(path, gridName);  // the child read this file without crashing: safe here
    }
    DecodedGrid decoded = transfer.decode();
    if (!decoded.log.empty()) std::cerr << decoded.log;
    Volume v = wrapGrid(decoded.grid, path, decoded.activeVoxels);
    v.nonFiniteCount = decoded.nonFiniteCount;
    v.valueMin = decoded.valueMin;
    v.valueMax = decoded.valueMax;
    v.file = path;
    return v;
}
}  // namespace

// Valid files of the layouts OpenVDB 3-10 write are read in process by vdbsplat's own reader
// (volume/vdb_reader.h), which checks every byte before it allocates or indexes from it;
// whatever it does not cover goes to OpenVDB's reader in a forked child (loadInChild).
Volume loadVolume(const std::string& path, const std::string& gridName) {
    checkVdbFile(path);
    std::optional<ReadGrid> read = readVdbGrid(path, gridName);
    if (!read) return loadInChild(path, gridName);
    Volume v = wrapTree(std::move(read->tree), std::move(read->name), std::move(read->map), path, read->activeVoxels);
    v.nonFiniteCount = read->nonFiniteCount;
    v.valueMin = read->valueMin;
    v.valueMax = read->valueMax;
    v.file = path;
    return v;
}

void writeVolume(const std::string& path, openvdb::FloatGrid::Ptr grid) { writeVolumes(path, {std::move(grid)}); }

void writeVolumes(const std::string& path, const std::vector<openvdb::FloatGrid::Ptr>& grids) {
    initOpenVdb();
    checkRegularOutputPath(path);
    const std::string target = resolveOutputPath(path);  // through a symbolic link, never replacing it
    const std::string tmp = temporaryPathFor(target);
    try {
        openvdb::io::File file(tmp);
        openvdb::GridCPtrVec all(grids.begin(), grids.end());
        file.write(all);
        file.close();
    } catch (const std::exception& e) {
        std::remove(tmp.c_str());
        std::string what = e.what();  // OpenVDB names the temporary file: name the output instead
        for (size_t at = what.find(tmp); at != std::string::npos; at = what.find(tmp, at + path.size()))
            what.replace(at, tmp.size(), path);
        throw Error(path + ": cannot write VDB file (" + what + ")");
    }
    // OpenVDB does not check its stream: a full disk leaves a truncated file and no error.
    // The structural pre-check finds a grid that ends past the end of the file.
    try {
        checkVdbStructure(tmp);
    } catch (const Error&) {
        std::remove(tmp.c_str());
        throw Error(path + ": cannot write VDB file (the written file is incomplete: disk full or file too large?)");
    }
    renameIntoPlace(tmp, target, path);
}

}  // namespace vdbsplat
