// volume/generate.cpp — procedural test volumes (see generate.h).
// Owns the leaf-parallel grid builder and the four generators: Yuan et al. 2003's
// Checker Box, Marschner & Lobb 1994's test signal (their eq. 1 with f_M = 6, α = 0.25),
// a smooth fog ball, and a hash-based fractal value-noise cloud whose threshold is
// chosen from a histogram so that the active count is close to the request, and random thin
// tubes and sheets (capsules along quadratic Bézier axes, discs), seeded, and an explosion
// (density + temperature: noisy lobes with a hot core), seeded.
#include "volume/generate.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <cstdio>
#include <numbers>

#include "util/error.h"
#include "volume/grid.h"

namespace vdbsplat {

namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using LeafT = openvdb::FloatTree::LeafNodeType;

// ---------------------------------------------------------------------------
// Leaf-parallel builder: fn(Coord, float&) -> bool (active?) is called for every
// voxel of @p domain; leaves are created independently and inserted in index order.
// ---------------------------------------------------------------------------

template <typename VoxelFn>
std::unique_ptr<LeafT> buildLeaf(const Coord& origin, const CoordBBox& domain, const VoxelFn& fn) {
    auto leaf = std::make_unique<LeafT>(origin, 0.0f, false);
    for (openvdb::Index n = 0; n < LeafT::SIZE; ++n) {
        const Coord xyz = leaf->offsetToGlobalCoord(n);
        float value = 0.0f;
        if (domain.isInside(xyz) && fn(xyz, value)) leaf->setValueOn(n, value);
    }
    if (leaf->isEmpty()) return nullptr;
    return leaf;
}

openvdb::FloatGrid::Ptr makeDensityGrid(const std::string& generator) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
    grid->insertMeta("generator", openvdb::StringMetadata(generator));
    return grid;
}

/// Calls leafFn(origin) -> unique_ptr<LeafT> (null when empty) for every leaf touching @p domain, in
/// parallel, then inserts the leaves in index order (the result does not depend on the thread count).
template <typename LeafFn>
openvdb::FloatGrid::Ptr buildGridFromLeaves(const CoordBBox& domain, const std::string& generator, const LeafFn& leafFn) {
    const Coord lo = domain.min() & ~7, hi = domain.max() & ~7;
    const int64_t nx = (hi.x() - lo.x()) / 8 + 1, ny = (hi.y() - lo.y()) / 8 + 1, nz = (hi.z() - lo.z()) / 8 + 1;
    std::vector<std::unique_ptr<LeafT>> leaves(static_cast<size_t>(nx * ny * nz));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t n = r.begin(); n != r.end(); ++n) {
            const int64_t i = static_cast<int64_t>(n);
            const Coord origin = lo + Coord(int(i % nx) * 8, int(i / nx % ny) * 8, int(i / (nx * ny)) * 8);
            leaves[n] = leafFn(origin);
        }
    });
    auto grid = makeDensityGrid(generator);
    auto& tree = grid->tree();
    for (auto& leaf : leaves)
        if (leaf) tree.addLeaf(leaf.release());
    return grid;
}

template <typename VoxelFn>
openvdb::FloatGrid::Ptr buildGrid(const CoordBBox& domain, const std::string& generator, const VoxelFn& fn) {
    return buildGridFromLeaves(domain, generator, [&](const Coord& origin) { return buildLeaf(origin, domain, fn); });
}

CoordBBox cube(int res) { return CoordBBox(Coord(0), Coord(res - 1)); }

// ---------------------------------------------------------------------------
// Cloud: fractal value noise (hash of lattice points, quintic-faded trilinear
// interpolation) in normalised coordinates u ∈ (0,1)³, plus a radial envelope.
// ---------------------------------------------------------------------------

constexpr int kCloudOctaves = 5;
constexpr double kCloudBaseFrequency = 4.0;  ///< lattice cells per domain side at octave 0
constexpr double kCloudNoiseAmplitude = 0.45;
constexpr double kCloudDomainFill = 0.3;      ///< target fraction of the cubic domain that is active
constexpr int kCloudHistogramBins = 1 << 16;
constexpr int64_t kCloudMaxSampledLeavesPerAxis = 24;  ///< the first threshold estimate reads at most 24³ whole leaves
constexpr double kCloudCandidateMargin = 1.3;  ///< keep ~30% more candidates than requested, then cut exactly
constexpr double kCloudTopFraction = 0.1;    ///< the densest 10% of active voxels have density 1

uint64_t mix64(uint64_t x) {  // splitmix64 finaliser
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

double latticeValue(uint64_t seed, int64_t x, int64_t y, int64_t z) {
    const uint64_t h = mix64(seed ^ (uint64_t(x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(y) * 0xC2B2AE3D27D4EB4Full) ^
                             (uint64_t(z) * 0x165667B19E3779F9ull));
    return double(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;  // [-1, 1)
}

double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/// Trilinear blend of 8 lattice values c[dz][dy][dx] with faded weights (shared by both evaluation paths,
/// so a voxel gets bit-identical values whether its lattice values were cached or not).
double blend(const double c[2][2][2], double u, double v, double w) {
    double row[2][2];
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy) row[dz][dy] = c[dz][dy][0] + u * (c[dz][dy][1] - c[dz][dy][0]);
    const double c0 = row[0][0] + v * (row[0][1] - row[0][0]), c1 = row[1][0] + v * (row[1][1] - row[1][0]);
    return c0 + w * (c1 - c0);
}

/// One axis of one octave: lattice coordinate t = ((i + 0.5) / side) * frequency + offset.
struct AxisPoint {
    int64_t cell;
    double weight;
};
AxisPoint axisPoint(int i, double side, double frequency, double offset) {
    const double t = ((i + 0.5) / side) * frequency + offset;
    const double f = std::floor(t);
    return {int64_t(f), fade(t - f)};
}

constexpr double octaveOffsetX(int octave) { return 17.0 * octave; }
uint64_t octaveSeed(uint64_t seed, int octave) { return mix64(seed + 0x51ED27ull * (octave + 1)); }

/// Normalised distance of voxel centre i from the domain centre along one axis (r = 1 at a face centre).
double radialOffset(int i, double side) { return 2.0 * ((i + 0.5) / side - 0.5); }

/// The cloud's scalar field: kCloudNoiseAmplitude · fBm(u) + (1 − r), u = (voxel + 0.5) / side.
struct CloudField {
    uint64_t seed;
    int64_t side;

    double noiseAt(const Coord& xyz, int octave, double frequency) const {
        const uint64_t s = octaveSeed(seed, octave);
        const AxisPoint px = axisPoint(xyz.x(), double(side), frequency, octaveOffsetX(octave));
        const AxisPoint py = axisPoint(xyz.y(), double(side), frequency, 0.0);
        const AxisPoint pz = axisPoint(xyz.z(), double(side), frequency, 0.0);
        double c[2][2][2];
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) c[dz][dy][dx] = latticeValue(s, px.cell + dx, py.cell + dy, pz.cell + dz);
        return blend(c, px.weight, py.weight, pz.weight);
    }

    double envelope(const Coord& xyz) const {
        const double s = double(side), x = radialOffset(xyz.x(), s), y = radialOffset(xyz.y(), s), z = radialOffset(xyz.z(), s);
        return 1.0 - std::sqrt(x * x + y * y + z * z);
    }

    /// Bounds of the field (|noise| < Σ amplitudes < 2, r ∈ [0, √3]).
    static double lowest() { return -kCloudNoiseAmplitude * 2.0 + 1.0 - std::sqrt(3.0); }
    static double highest() { return kCloudNoiseAmplitude * 2.0 + 1.0; }
};

/// The lattice values one octave needs for one 8³ leaf, hashed once instead of 8 times per voxel.
struct OctaveCache {
    AxisPoint x[8], y[8], z[8];
    int64_t x0 = 0, y0 = 0, z0 = 0;
    int nx = 0, ny = 0, nz = 0;
    std::vector<double> values;  ///< [z][y][x] lattice values; empty when direct evaluation is cheaper
    double maxValue = 1.0;       ///< bound on the interpolated noise over the leaf

    static constexpr size_t kMaxCached = 2048;

    OctaveCache(const CloudField& field, const Coord& origin, int octave, double frequency) {
        const double s = double(field.side);
        for (int k = 0; k < 8; ++k) {
            x[k] = axisPoint(origin.x() + k, s, frequency, octaveOffsetX(octave));
            y[k] = axisPoint(origin.y() + k, s, frequency, 0.0);
            z[k] = axisPoint(origin.z() + k, s, frequency, 0.0);
        }
        x0 = x[0].cell, y0 = y[0].cell, z0 = z[0].cell;
        nx = int(x[7].cell - x0 + 2), ny = int(y[7].cell - y0 + 2), nz = int(z[7].cell - z0 + 2);
        if (size_t(nx) * ny * nz > kMaxCached) return;
        const uint64_t seed = octaveSeed(field.seed, octave);
        values.resize(size_t(nx) * ny * nz);
        maxValue = -1.0;
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) {
                    const double v = latticeValue(seed, x0 + i, y0 + j, z0 + k);
                    values[(size_t(k) * ny + j) * nx + i] = v;
                    maxValue = std::max(maxValue, v);  // interpolation is a convex combination
                }
    }

    double at(int i, int j, int k) const {  // voxel offsets in the leaf; values must be cached
        double c[2][2][2];
        const int64_t bx = x[i].cell - x0, by = y[j].cell - y0, bz = z[k].cell - z0;
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) c[dz][dy][dx] = values[(size_t(bz + dz) * ny + (by + dy)) * nx + (bx + dx)];
        return blend(c, x[i].weight, y[j].weight, z[k].weight);
    }
};

/// Largest envelope (1 − r) over the voxel centres of the leaf at @p origin.
double leafEnvelopeBound(const CloudField& field, const Coord& origin) {
    const double s = double(field.side);
    double r2 = 0.0;
    for (int a = 0; a < 3; ++a) {
        const double lo = radialOffset(origin[a], s), hi = radialOffset(origin[a] + 7, s);
        const double d = lo > 0.0 ? lo : hi < 0.0 ? -hi : 0.0;
        r2 += d * d;
    }
    return 1.0 - std::sqrt(r2);
}

/// Calls fn(offset, f) with the field value f of every voxel of @p domain in the leaf at @p origin,
/// unless no voxel of the leaf can exceed @p cullAtOrBelow (a bound from the cached lattice values).
template <typename Fn>
void forEachCloudVoxel(const CloudField& field, const Coord& origin, const CoordBBox& domain, double cullAtOrBelow,
                       const Fn& fn) {
    std::vector<OctaveCache> octaves;
    octaves.reserve(kCloudOctaves);
    double bound = 0.0, amplitude = 1.0, frequency = kCloudBaseFrequency;
    for (int o = 0; o < kCloudOctaves; ++o, amplitude *= 0.5, frequency *= 2.0) {
        octaves.emplace_back(field, origin, o, frequency);
        bound += amplitude * octaves.back().maxValue;
    }
    if (kCloudNoiseAmplitude * bound + leafEnvelopeBound(field, origin) <= cullAtOrBelow) return;
    for (openvdb::Index n = 0; n < LeafT::SIZE; ++n) {
        const Coord xyz = LeafT::offsetToLocalCoord(n) + origin;
        if (!domain.isInside(xyz)) continue;
        const Coord d = xyz - origin;
        double noise = 0.0;
        amplitude = 1.0, frequency = kCloudBaseFrequency;
        for (int o = 0; o < kCloudOctaves; ++o, amplitude *= 0.5, frequency *= 2.0)
            noise += amplitude * (octaves[o].values.empty() ? field.noiseAt(xyz, o, frequency)
                                                            : octaves[o].at(d.x(), d.y(), d.z()));
        fn(n, kCloudNoiseAmplitude * noise + field.envelope(xyz));
    }
}

/// Builds one leaf of candidates: voxels of @p domain whose field exceeds @p floor, holding the field value.
std::unique_ptr<LeafT> buildCandidateLeaf(const CloudField& field, const Coord& origin, const CoordBBox& domain,
                                          double floor) {
    auto leaf = std::make_unique<LeafT>(origin, 0.0f, false);
    forEachCloudVoxel(field, origin, domain, floor, [&](openvdb::Index n, double f) {
        if (f > floor) leaf->setValueOn(n, static_cast<float>(f));
    });
    if (leaf->isEmpty()) return nullptr;
    return leaf;
}

/// A fixed-range histogram; bins are integer counts, so merging per-thread copies is order-independent.
struct Histogram {
    double lo, hi;
    std::vector<uint64_t> bins = std::vector<uint64_t>(kCloudHistogramBins, 0);

    void add(double f) {
        const double scale = kCloudHistogramBins / (hi - lo);
        bins[std::clamp<int64_t>(int64_t(std::floor((f - lo) * scale)), 0, kCloudHistogramBins - 1)]++;
    }
    void merge(const Histogram& other) {
        for (int b = 0; b < kCloudHistogramBins; ++b) bins[b] += other.bins[b];
    }
    uint64_t total() const {
        uint64_t n = 0;
        for (uint64_t c : bins) n += c;
        return n;
    }
    /// The value above which about @p count samples lie (linear within a bin); below lo when count ≥ total.
    double valueWithCountAbove(double count) const {
        const double width = (hi - lo) / kCloudHistogramBins;
        double above = 0.0;  // samples in bins > b
        for (int b = kCloudHistogramBins - 1; b >= 0; --b) {
            const double inBin = double(bins[b]);
            if (above + inBin >= count && inBin > 0.0) return lo + width * (b + 1 - (count - above) / inBin);
            above += inBin;
        }
        return lo - width;
    }
};

/// Histogram of the field over every voxel of every @p stride-th leaf along each axis (whole leaves,
/// so every sub-leaf phase is sampled); a first estimate of the threshold.
Histogram sampledFieldHistogram(const CloudField& field, int64_t stride) {
    const CoordBBox domain = cube(int(field.side));
    const int64_t m = ((field.side + 7) / 8 + stride - 1) / stride;
    const Histogram empty{CloudField::lowest(), CloudField::highest()};
    tbb::combinable<Histogram> partial([&] { return empty; });
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, m * m * m), [&](const tbb::blocked_range<int64_t>& r) {
        auto& hist = partial.local();
        for (int64_t n = r.begin(); n != r.end(); ++n) {
            const Coord origin(int(n % m * stride * 8), int(n / m % m * stride * 8), int(n / (m * m) * stride * 8));
            forEachCloudVoxel(field, origin, domain, -std::numeric_limits<double>::infinity(),
                              [&](openvdb::Index, double f) { hist.add(f); });
        }
    });
    Histogram total = empty;
    partial.combine_each([&](const Histogram& h) { total.merge(h); });
    return total;
}

/// Exact histogram of the active values of @p tree over [lo, hi].
Histogram activeValueHistogram(openvdb::FloatTree& tree, double lo, double hi) {
    const Histogram empty{lo, hi};
    tbb::combinable<Histogram> partial([&] { return empty; });
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
    tbb::parallel_for(leaves.leafRange(), [&](const auto& range) {
        auto& hist = partial.local();
        for (auto leaf = range.begin(); leaf; ++leaf)
            for (auto it = leaf->cbeginValueOn(); it; ++it) hist.add(*it);
    });
    Histogram total = empty;
    partial.combine_each([&](const Histogram& h) { total.merge(h); });
    return total;
}

/// Turns candidate field values into densities: f > threshold → clamp((f − threshold)/width), else inactive.
void cutCandidates(openvdb::FloatTree& tree, double threshold, double width) {
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
    leaves.foreach([&](LeafT& leaf, size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const double f = *it;
            if (f > threshold) it.setValue(static_cast<float>(std::clamp((f - threshold) / width, 1e-6, 1.0)));
            else leaf.setValueOff(it.pos(), 0.0f);
        }
    });
    openvdb::tools::pruneInactive(tree);
}


// ---------------------------------------------------------------------------
// Tubes: counter-based random numbers (splitmix64 of seed and index), a fixed
// layout, then every leaf evaluates only the capsule segments and discs whose
// bounding boxes touch it.
// ---------------------------------------------------------------------------

constexpr int kTubeSegments = 32;          ///< polyline segments per Bézier axis
constexpr double kTubeMarginFraction = 0.06;  ///< endpoints stay this far (× res) inside the box
constexpr double kTubeMinLengthFraction = 0.6;  ///< endpoints at least this far apart (× res)
constexpr double kTubeBendFraction = 0.2;  ///< control point offset from the midpoint, up to ± this × res
constexpr double kSheetExtentMin = 0.06, kSheetExtentMax = 0.10;  ///< disc radius (× res)

/// Uniform [0, 1) from (seed, stream, index): the layout does not depend on evaluation order.
double uniform01(uint64_t seed, uint64_t stream, uint64_t index) {
    const uint64_t h = mix64(mix64(seed ^ 0xA0761D6478BD642Full) ^ (stream * 0xE7037ED1A0B428DBull) ^ index);
    return double(h >> 11) * (1.0 / 9007199254740992.0);
}

openvdb::Vec3d bezier(const TubePrimitive& t, double u) {
    return (1.0 - u) * (1.0 - u) * t.a + 2.0 * u * (1.0 - u) * t.m + u * u * t.b;
}

double segmentDistance(const openvdb::Vec3d& p0, const openvdb::Vec3d& p1, const openvdb::Vec3d& x) {
    const openvdb::Vec3d d = p1 - p0;
    const double len2 = d.lengthSqr();
    const double u = len2 > 0.0 ? std::clamp((x - p0).dot(d) / len2, 0.0, 1.0) : 0.0;
    return (x - (p0 + u * d)).length();
}

/// What a leaf evaluates: one capsule segment of a tube (sheet = false) or one disc.
struct TubePiece {
    const TubePrimitive* owner;
    openvdb::Vec3d p0, p1;  ///< segment ends (tubes)
    CoordBBox box;          ///< voxels where its density may be > 0
};

CoordBBox pieceBox(openvdb::Vec3d lo, openvdb::Vec3d hi, double pad) {
    return CoordBBox(Coord(int(std::floor(lo.x() - pad)), int(std::floor(lo.y() - pad)), int(std::floor(lo.z() - pad))),
                     Coord(int(std::ceil(hi.x() + pad)), int(std::ceil(hi.y() + pad)), int(std::ceil(hi.z() + pad))));
}

std::vector<TubePiece> tubePieces(const std::vector<TubePrimitive>& layout) {
    std::vector<TubePiece> pieces;
    for (const TubePrimitive& t : layout) {
        const double pad = t.r + kTubeFalloffVoxels;
        if (t.sheet) {
            const openvdb::Vec3d e(t.extent);
            pieces.push_back({&t, t.a, t.a, pieceBox(t.a - e, t.a + e, pad)});
            continue;
        }
        for (int k = 0; k < kTubeSegments; ++k) {
            const openvdb::Vec3d p0 = bezier(t, double(k) / kTubeSegments), p1 = bezier(t, double(k + 1) / kTubeSegments);
            pieces.push_back({&t, p0, p1, pieceBox(minComponent(p0, p1), maxComponent(p0, p1), pad)});
        }
    }
    return pieces;
}

double pieceDistance(const TubePiece& p, const openvdb::Vec3d& x) {
    return p.owner->sheet ? tubeDistance(*p.owner, x) : segmentDistance(p.p0, p.p1, x);
}

std::unique_ptr<LeafT> buildTubeLeaf(const std::vector<TubePiece>& pieces, const Coord& origin, const CoordBBox& domain) {
    const CoordBBox leafBox(origin, origin + Coord(7));
    std::vector<const TubePiece*> near;
    for (const TubePiece& p : pieces)
        if (p.box.hasOverlap(leafBox)) near.push_back(&p);
    if (near.empty()) return nullptr;
    return buildLeaf(origin, domain, [&](const Coord& c, float& v) {
        const openvdb::Vec3d x(c.x(), c.y(), c.z());
        double best = 0.0;
        for (const TubePiece* p : near)
            if (p->box.isInside(c)) best = std::max(best, tubeProfile(pieceDistance(*p, x), p->owner->r));
        v = static_cast<float>(best);
        return v > 0.0f;
    });
}

// ---------------------------------------------------------------------------
// Explosion: a fireball of random lobes (soft union of balls) roughened by fractal value
// noise; temperature is a hotter, noisier core inside the smoke. Counter-based random
// numbers as the tubes (one draw per statement), so every compiler makes the same layout.
// ---------------------------------------------------------------------------

constexpr int kExplosionLobes = 9;
constexpr double kExplosionRadius = 0.36;      ///< main ball radius (× (res − 1))
constexpr double kExplosionNoise = 0.45;       ///< fBm amplitude added to the lobe field
constexpr double kExplosionEdge = 0.30;        ///< field width over which density rises 0 → 1
constexpr double kExplosionCoreStart = 0.30;   ///< lobe field where the temperature starts
constexpr double kExplosionCoreWidth = 0.55;   ///< ... and the width over which it reaches 1

struct ExplosionLobe {
    openvdb::Vec3d centre;
    double radius;
};

std::vector<ExplosionLobe> explosionLayout(int res, uint64_t seed) {
    uint64_t draw = 0;
    const auto u = [&](uint64_t stream) { return uniform01(seed, stream, draw++); };
    const double c = 0.5 * (res - 1), R = kExplosionRadius * (res - 1);
    std::vector<ExplosionLobe> lobes{{openvdb::Vec3d(c, c, c - 0.1 * R), 0.75 * R}};
    for (int i = 0; i < kExplosionLobes; ++i) {
        // A direction biased upwards (+z: the fireball rises), one draw per statement.
        const double z = 1.2 * u(7) - 0.4;
        const double phi = 2.0 * std::numbers::pi * u(7);
        const double reach = 0.25 + 0.4 * u(8);
        const double size = 0.3 + 0.25 * u(9);
        const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
        const openvdb::Vec3d dir(rxy * std::cos(phi), rxy * std::sin(phi), z);
        lobes.push_back({openvdb::Vec3d(c, c, c) + reach * R * dir, size * R});
    }
    return lobes;
}

/// The soft union of the lobes: max_i (1 − |x − c_i| / r_i) (1 at a centre, 0 on its sphere).
double lobeField(const std::vector<ExplosionLobe>& lobes, const openvdb::Vec3d& x) {
    double best = -1e9;
    for (const ExplosionLobe& l : lobes) best = std::max(best, 1.0 - (x - l.centre).length() / l.radius);
    return best;
}

/// Fractal value noise in [−1, 1) (4 octaves of the cloud's lattice noise, normalised).
double explosionNoise(const CloudField& field, const Coord& xyz) {
    double sum = 0.0, amplitude = 1.0, norm = 0.0, frequency = 6.0;
    for (int o = 0; o < 4; ++o, amplitude *= 0.5, frequency *= 2.0) {
        sum += amplitude * field.noiseAt(xyz, o, frequency);
        norm += amplitude;
    }
    return sum / norm;
}

}  // namespace

std::vector<openvdb::FloatGrid::Ptr> makeExplosion(int res, uint64_t seed) {
    const std::vector<ExplosionLobe> lobes = explosionLayout(res, seed);
    const CloudField smoke{mix64(seed ^ 0x5A0E), res}, heat{mix64(seed ^ 0x4EA7), res};
    const auto densityAt = [&](const Coord& c) {
        const double f = lobeField(lobes, openvdb::Vec3d(c.x(), c.y(), c.z())) + kExplosionNoise * explosionNoise(smoke, c);
        return std::clamp(f / kExplosionEdge, 0.0, 1.0);
    };
    const auto temperatureAt = [&](const Coord& c) {
        const double f = lobeField(lobes, openvdb::Vec3d(c.x(), c.y(), c.z())) + 0.6 * explosionNoise(heat, c);
        return std::clamp((f - kExplosionCoreStart) / kExplosionCoreWidth, 0.0, 1.0);
    };
    char label[96];
    std::snprintf(label, sizeof label, "explosion res=%d seed=%llu", res, (unsigned long long)seed);
    auto density = buildGrid(cube(res), label, [&](const Coord& c, float& v) {
        v = float(densityAt(c));
        return v > 0.f;
    });
    auto temperature = buildGrid(cube(res), label, [&](const Coord& c, float& v) {
        v = float(temperatureAt(c));
        return v > 0.f && densityAt(c) > 0.0;  // inside the smoke
    });
    temperature->setName("temperature");
    temperature->setGridClass(openvdb::GRID_UNKNOWN);
    return {density, temperature};
}

namespace {
}  // namespace

// ---------------------------------------------------------------------------

const std::vector<std::string>& generatorKinds() {
    static const std::vector<std::string> kinds{"checkerbox", "marschner-lobb", "sphere", "cloud", "tubes", "explosion"};
    return kinds;
}

void GenerateOptions::validate() {
    const auto& kinds = generatorKinds();
    if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end())
        throw Error("generate: unknown kind '" + kind +
                    "' (choose checkerbox, marschner-lobb, sphere, cloud, tubes or explosion)");
    const bool cloud = kind == "cloud", tubes = kind == "tubes", explosion = kind == "explosion";
    if (cloud && res) throw Error("--res: not used by 'cloud' (its size follows --active)");
    if (!cloud && active) throw Error("--active: only 'cloud' takes an active voxel count");
    if (!cloud && !tubes && !explosion && seed) throw Error("--seed: only 'cloud', 'tubes' and 'explosion' are random");
    if (explosion && !seed) seed = kDefaultCloudSeed;
    if (!tubes && count) throw Error("--count: only 'tubes' takes a tube count");
    if (!tubes && sheets) throw Error("--sheets: only 'tubes' takes a sheet count");
    if (!tubes && (radiusMin || radiusMax)) throw Error("--radius-min/--radius-max: only 'tubes' takes a radius");
    if (tubes) validateTubes();
    if (cloud) {
        if (!active) active = kDefaultCloudActive;
        if (!seed) seed = kDefaultCloudSeed;
        if (*active < 1 || *active > kMaxGeneratedVoxels)
            throw Error("--active: " + std::to_string(*active) + " is outside [1, " +
                        std::to_string(kMaxGeneratedVoxels) + "]");
        return;
    }
    if (!res)
        res = kind == "checkerbox" ? kDefaultCheckerRes
              : kind == "sphere"   ? kDefaultSphereRes
              : tubes              ? kDefaultTubesRes
              : explosion          ? kDefaultExplosionRes
                                   : kDefaultMarschnerLobbRes;
    const int minRes = kind == "sphere" ? 3 : explosion ? 8 : 2;
    if (*res < minRes || *res > kMaxGenerateRes)
        throw Error("--res: " + std::to_string(*res) + " is outside [" + std::to_string(minRes) + ", " +
                    std::to_string(kMaxGenerateRes) + "]");
    const double cubeVoxels = std::pow(double(*res), 3.0);
    const double voxels = kind == "sphere" ? cubeVoxels * std::numbers::pi / 6.0 : tubes ? 0.0 : cubeVoxels;
    if (voxels > double(kMaxGeneratedVoxels))
        throw Error("--res: " + std::to_string(*res) + " would make about " + std::to_string(uint64_t(voxels)) +
                    " active voxels, more than the limit of " + std::to_string(kMaxGeneratedVoxels));
}

std::vector<openvdb::FloatGrid::Ptr> generateGrids(GenerateOptions options) {
    options.validate();
    if (options.kind == "explosion") return makeExplosion(*options.res, *options.seed);
    return {generateVolume(options)};
}

openvdb::FloatGrid::Ptr generateVolume(GenerateOptions options) {
    options.validate();
    if (options.kind == "explosion") return makeExplosion(*options.res, *options.seed).front();
    if (options.kind == "checkerbox") return makeCheckerBox(*options.res);
    if (options.kind == "marschner-lobb") return makeMarschnerLobb(*options.res);
    if (options.kind == "sphere") return makeSphere(*options.res);
    if (options.kind == "tubes")
        return makeTubes(*options.res, *options.count, *options.sheets, *options.radiusMin, *options.radiusMax, *options.seed);
    return makeCloud(*options.active, *options.seed);
}

openvdb::FloatGrid::Ptr makeCheckerBox(int res) {
    const auto cell = [res](int i) { return int64_t(i) * kCheckerCellsPerSide / res; };
    return buildGrid(cube(res), "checkerbox res=" + std::to_string(res), [&](const Coord& c, float& v) {
        v = (cell(c.x()) + cell(c.y()) + cell(c.z())) % 2 == 0 ? kCheckerDensityEven : kCheckerDensityOdd;
        return true;
    });
}

double marschnerLobb(double x, double y, double z) {
    constexpr double pi = std::numbers::pi;
    const double r = std::sqrt(x * x + y * y);
    const double rho = std::cos(2.0 * pi * kMarschnerLobbFM * std::cos(pi * r / 2.0));
    return (1.0 - std::sin(pi * z / 2.0) + kMarschnerLobbAlpha * (1.0 + rho)) / (2.0 * (1.0 + kMarschnerLobbAlpha));
}

openvdb::FloatGrid::Ptr makeMarschnerLobb(int res) {
    const double step = 2.0 / (res - 1);
    return buildGrid(cube(res), "marschner-lobb res=" + std::to_string(res), [&](const Coord& c, float& v) {
        const double f = marschnerLobb(-1.0 + step * c.x(), -1.0 + step * c.y(), -1.0 + step * c.z());
        v = static_cast<float>(std::clamp(f, 0.0, 1.0));
        return true;
    });
}

openvdb::FloatGrid::Ptr makeSphere(int res) {
    const double centre = (res - 1) / 2.0, radius2 = centre * centre;
    return buildGrid(cube(res), "sphere res=" + std::to_string(res), [&](const Coord& c, float& v) {
        const double dx = c.x() - centre, dy = c.y() - centre, dz = c.z() - centre;
        const double q = (dx * dx + dy * dy + dz * dz) / radius2;
        if (q >= 1.0) return false;
        v = static_cast<float>((1.0 - q) * (1.0 - q));
        return v > 0.0f;
    });
}

openvdb::FloatGrid::Ptr makeCloud(uint64_t active, uint64_t seed) {
    const int64_t side = std::max<int64_t>(2, std::llround(std::cbrt(double(active) / kCloudDomainFill)));
    const CloudField field{seed, side};
    const CoordBBox domain = cube(int(side));
    const std::string label = "cloud active=" + std::to_string(active) + " seed=" + std::to_string(seed);
    // 1. A first estimate from a sample of whole leaves gives a floor a little below the threshold.
    const int64_t stride = ((side + 7) / 8 + kCloudMaxSampledLeavesPerAxis - 1) / kCloudMaxSampledLeavesPerAxis;
    const Histogram sampled = sampledFieldHistogram(field, stride);
    const double toSamples = double(sampled.total()) / std::pow(double(side), 3.0);
    // 2. Keep every voxel above the floor with its field value (lower the floor until there are enough).
    for (double margin = kCloudCandidateMargin;; margin *= 2.0) {
        const double floor = sampled.valueWithCountAbove(double(active) * margin * toSamples);
        auto grid = buildGridFromLeaves(domain, label, [&](const Coord& origin) {
            return buildCandidateLeaf(field, origin, domain, floor);
        });
        const uint64_t candidates = grid->tree().activeVoxelCount();
        if (candidates < active && floor >= CloudField::lowest()) continue;
        // 3. The exact threshold from the candidates' values, then cut.
        const Histogram exact = activeValueHistogram(grid->tree(), floor, CloudField::highest());
        const double threshold = exact.valueWithCountAbove(double(active));
        const double top = exact.valueWithCountAbove(double(active) * kCloudTopFraction);
        cutCandidates(grid->tree(), threshold, std::max(top - threshold, 1e-6));
        return grid;
    }
}

void GenerateOptions::validateTubes() {
    if (!seed) seed = kDefaultCloudSeed;
    if (!count) count = kDefaultTubeCount;
    if (!sheets) sheets = kDefaultSheetCount;
    if (!radiusMin) radiusMin = kDefaultTubeRadiusMin;
    if (!radiusMax) radiusMax = std::max(kDefaultTubeRadiusMax, *radiusMin);
    if (*count < 0 || *count > kMaxTubeCount)
        throw Error("--count: " + std::to_string(*count) + " is outside [0, " + std::to_string(kMaxTubeCount) + "]");
    if (*sheets < 0 || *sheets > kMaxTubeCount)
        throw Error("--sheets: " + std::to_string(*sheets) + " is outside [0, " + std::to_string(kMaxTubeCount) + "]");
    const auto inRange = [](double r) { return r >= kMinTubeRadius && r <= kMaxTubeRadius; };
    if (!inRange(*radiusMin) || !inRange(*radiusMax))
        throw Error("--radius-min/--radius-max: radii must lie in [" + std::to_string(kMinTubeRadius) + ", " +
                    std::to_string(kMaxTubeRadius) + "] voxels");
    if (*radiusMin > *radiusMax) throw Error("--radius-min: larger than --radius-max");
}

double tubeProfile(double d, double r) {
    if (d <= r) return 1.0;
    const double s = (d - r) / kTubeFalloffVoxels;
    return s < 1.0 ? (1.0 - s * s) * (1.0 - s * s) : 0.0;
}

double tubeDistance(const TubePrimitive& t, const openvdb::Vec3d& x) {
    if (t.sheet) {  // disc of radius `extent` in the plane through a with normal n
        const openvdb::Vec3d q = x - t.a;
        const double h = q.dot(t.n);
        const double rho = (q - h * t.n).length();
        const double out = std::max(rho - t.extent, 0.0);
        return std::sqrt(h * h + out * out);
    }
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < kTubeSegments; ++k)
        best = std::min(best, segmentDistance(bezier(t, double(k) / kTubeSegments), bezier(t, double(k + 1) / kTubeSegments), x));
    return best;
}

std::vector<TubePrimitive> tubeLayout(int res, int count, int sheets, double radiusMin, double radiusMax, uint64_t seed) {
    const double lo = kTubeMarginFraction * (res - 1), hi = (res - 1) - lo;
    std::vector<TubePrimitive> layout;
    uint64_t draw = 0;  // index of the next random number
    const auto u = [&](uint64_t stream) { return uniform01(seed, stream, draw++); };
    const auto inBox = [&](uint64_t stream) {
        const double x = u(stream), y = u(stream), z = u(stream);
        return openvdb::Vec3d(lo + x * (hi - lo), lo + y * (hi - lo), lo + z * (hi - lo));
    };
    for (int i = 0; i < count; ++i) {
        TubePrimitive t;
        t.a = inBox(1), t.b = inBox(1);
        for (int tries = 0; tries < 64 && (t.b - t.a).length() < kTubeMinLengthFraction * res; ++tries) t.b = inBox(1);
        // One draw per statement: the order in which a constructor's arguments are evaluated is
        // unspecified (GCC and clang differ), and each draw advances the counter. z, y, x is
        // the order of the catalogued layout (34 740 voxels).
        const double bz = u(2), by = u(2), bx = u(2);
        const openvdb::Vec3d bend(bx - 0.5, by - 0.5, bz - 0.5);
        t.m = 0.5 * (t.a + t.b) + 2.0 * kTubeBendFraction * res * bend;
        t.m = openvdb::Vec3d(std::clamp(t.m.x(), lo, hi), std::clamp(t.m.y(), lo, hi), std::clamp(t.m.z(), lo, hi));
        t.r = radiusMin + u(3) * (radiusMax - radiusMin);
        layout.push_back(t);
    }
    for (int i = 0; i < sheets; ++i) {
        TubePrimitive s;
        s.sheet = true;
        const double mid = 0.5 * (res - 1), spread = 0.2 * (res - 1);
        const double az = u(4), ay = u(4), ax = u(4);  // one draw per statement, as above
        s.a = openvdb::Vec3d(mid + spread * (2.0 * ax - 1.0), mid + spread * (2.0 * ay - 1.0), mid + spread * (2.0 * az - 1.0));
        // A uniform direction: z uniform in [−1, 1], azimuth uniform (Archimedes).
        const double z = 2.0 * u(5) - 1.0, phi = 2.0 * std::numbers::pi * u(5), rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
        s.n = openvdb::Vec3d(rxy * std::cos(phi), rxy * std::sin(phi), z);
        s.extent = (kSheetExtentMin + u(6) * (kSheetExtentMax - kSheetExtentMin)) * res;
        s.r = radiusMin + u(3) * (radiusMax - radiusMin);
        layout.push_back(s);
    }
    return layout;
}

openvdb::FloatGrid::Ptr makeTubes(int res, int count, int sheets, double radiusMin, double radiusMax, uint64_t seed) {
    const std::vector<TubePrimitive> layout = tubeLayout(res, count, sheets, radiusMin, radiusMax, seed);
    const std::vector<TubePiece> pieces = tubePieces(layout);
    char label[160];
    std::snprintf(label, sizeof label, "tubes res=%d count=%d sheets=%d radius=%g..%g seed=%llu", res, count, sheets,
                  radiusMin, radiusMax, (unsigned long long)seed);
    return buildGridFromLeaves(cube(res), label, [&](const Coord& origin) { return buildTubeLeaf(pieces, origin, cube(res)); });
}

}  // namespace vdbsplat
