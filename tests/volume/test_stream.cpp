// tests/volume/test_stream.cpp — the depth-ordered voxel stream (DESIGN §5) against brute force.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <map>
#include <tuple>

#include "camera/camera.h"
#include "volume/generate.h"
#include "volume/grid.h"
#include "volume/stream.h"

namespace vdbsplat {
namespace {

ClassificationTable constantTable(float sigma) {
    return ClassificationTable(std::vector<Classified>(ClassificationTable::kSize, Classified{glm::vec3(1.f), sigma}),
                               0.f, 1.f);
}

/// A cloud: sparse, irregular leaves and values; deterministic.
const Volume& cloud() {
    static const Volume v = makeVolume(makeCloud(200000, 7), "cloud");
    return v;
}

struct Streamed {
    std::vector<VoxelBatch> batches;
    uint64_t voxels = 0, culled = 0;
    size_t largestBatch = 0;
};

/// The default framing of @p v at @p size² pixels and @p distance times the framing distance.
Camera framedCamera(const Volume& v, int size, double distance = 1.0) {
    glm::dvec3 lo, hi;
    v.worldBounds(lo, hi);
    CameraSpec spec;
    spec.width = spec.height = size;
    spec.distance = distance;
    return makeCamera(spec, lo, hi);
}

Streamed streamAll(const Volume& v, const Camera& camera, const ClassificationTable& table) {
    VoxelStream stream(v, camera, table);
    Streamed s;
    VoxelBatch batch;
    while (stream.next(batch)) {
        s.voxels += batch.size();
        s.largestBatch = std::max(s.largestBatch, batch.size());
        s.batches.push_back(batch);
    }
    s.culled = stream.culledVoxels();
    return s;
}

// Windows come out front to back: window slab ranges increase, every voxel lies in its
// window's slabs, and the view positions are the camera's transform of the voxel centres.
TEST(Stream, WindowsAreFrontToBackAndVoxelsInTheirSlabs) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 128);
    const ClassificationTable table = constantTable(0.2f);
    VoxelStream stream(v, camera, table);
    VoxelBatch batch;
    int64_t lastEnd = std::numeric_limits<int64_t>::min();
    int windows = 0;
    while (stream.next(batch)) {
        ++windows;
        EXPECT_GE(batch.slabBegin, lastEnd);
        EXPECT_LT(batch.slabBegin, batch.slabEnd);
        lastEnd = batch.slabEnd;
        for (size_t i = 0; i < batch.size(); ++i) {
            const auto slab = int64_t(std::floor(batch.distance[i] / stream.slabLength()));
            ASSERT_GE(slab, batch.slabBegin - 1) << "voxel before its window";  // float rounding at the edge
            ASSERT_LE(slab, batch.slabEnd) << "voxel after its window";
            ASSERT_NEAR(batch.distance[i], glm::length(batch.viewPos[i]), 1e-3f * batch.distance[i]);
        }
    }
    EXPECT_GE(windows, 5);  // 200k voxels in windows of about 32k: streamed, not all at once
}

// Every active voxel in front of the eye and inside the frustum comes out exactly once, with its
// classification; σ = 0 voxels never do.
TEST(Stream, EveryVisibleVoxelExactlyOnce) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 96);  // framed: everything visible
    const ClassificationTable table = constantTable(0.2f);
    const Streamed s = streamAll(v, camera, table);
    EXPECT_EQ(s.voxels + s.culled, v.activeVoxels);
    EXPECT_EQ(s.voxels, v.activeVoxels);  // the framed view sees every voxel
    std::map<std::tuple<int, int, int>, int> seen;
    for (const VoxelBatch& b : s.batches)
        for (size_t i = 0; i < b.size(); ++i) {
            EXPECT_FLOAT_EQ(b.sigma[i], 0.2f);
            const glm::vec3 p = b.viewPos[i];
            ++seen[{int(std::lround(p.x * 64)), int(std::lround(p.y * 64)), int(std::lround(p.z * 64))}];
        }
    for (const auto& [key, count] : seen) ASSERT_EQ(count, 1);
    EXPECT_EQ(seen.size(), v.activeVoxels);
    // A transparent transfer function streams nothing.
    EXPECT_EQ(streamAll(v, camera, constantTable(0.f)).voxels, 0u);
}

// Behind the eye and outside the frustum costs almost nothing: an eye inside the volume looking
// out along +x streams only the voxels in its view cone (with the kernel margin) and culls the
// rest by whole blocks.
TEST(Stream, CullsBehindTheEyeAndOutsideTheFrustum) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    grid->denseFill(openvdb::CoordBBox({-64, -64, -64}, {63, 63, 63}), 1.f, true);
    grid->tree().voxelizeActiveTiles();
    const Volume v = makeVolume(grid, "cube");
    const Camera camera({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 20.0, 64, 64);
    const Streamed s = streamAll(v, camera, constantTable(0.01f));
    EXPECT_EQ(s.voxels + s.culled, v.activeVoxels);
    // The 20° cone out to x = 64 holds about (64³/3)·(2·tan10°)² ≈ 0.012 of the 128³ voxels.
    EXPECT_LT(double(s.voxels), 0.05 * double(v.activeVoxels));
    EXPECT_GT(double(s.voxels), 0.005 * double(v.activeVoxels));
    // Nothing streamed lies behind the eye beyond the kernel margin, and the windows stay small.
    for (const VoxelBatch& b : s.batches)
        for (size_t i = 0; i < b.size(); ++i) ASSERT_GT(b.viewPos[i].z, -2.0f - 8.0f * std::sqrt(3.0f));
    EXPECT_LT(s.largestBatch, v.activeVoxels / 20);
}

// The batches are a function of the scene only (ordering inside a window included), so
// everything downstream is deterministic.
TEST(Stream, SameInputSameBatches) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 64, 0.6);
    const ClassificationTable table = constantTable(0.3f);
    const Streamed a = streamAll(v, camera, table), b = streamAll(v, camera, table);
    ASSERT_EQ(a.batches.size(), b.batches.size());
    for (size_t k = 0; k < a.batches.size(); ++k) {
        ASSERT_EQ(a.batches[k].viewPos, b.batches[k].viewPos);
        ASSERT_EQ(a.batches[k].slabBegin, b.batches[k].slabBegin);
    }
}

// Nor on the thread count: a window's blocks are extracted in parallel into buffers of a fixed
// number of blocks each, and released in block order, whatever thread extracted which block.
// With one thread, two and four, every batch holds the same records in the same order.
TEST(Stream, BatchesDoNotDependOnTheThreadCount) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 64, 0.8);
    const ClassificationTable table = constantTable(0.3f);
    const auto with = [&](int threads) {
        Streamed s;
        tbb::task_arena(threads).execute([&] { s = streamAll(v, camera, table); });
        return s;
    };
    const Streamed one = with(1);
    ASSERT_GT(one.batches.size(), 2u);
    for (int threads : {2, 4}) {
        const Streamed many = with(threads);
        ASSERT_EQ(one.batches.size(), many.batches.size()) << threads << " threads";
        for (size_t k = 0; k < one.batches.size(); ++k) {
            ASSERT_EQ(one.batches[k].viewPos, many.batches[k].viewPos) << threads << " threads, batch " << k;
            ASSERT_EQ(one.batches[k].sigma, many.batches[k].sigma) << threads << " threads, batch " << k;
            ASSERT_EQ(one.batches[k].members, many.batches[k].members) << threads << " threads, batch " << k;
        }
    }
}

// maxWindowVoxels bounds the windows: a window over the bound makes the next one half as
// many slabs deep (down to one), so memory follows the densest slab rather than the densest
// eight. The same voxels come out in the same slabs either way: windows split only at slab
// boundaries.
TEST(Stream, WindowsNarrowWhileOverTheVoxelBound) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 96);
    const ClassificationTable table = constantTable(0.2f);
    StreamOptions narrow;
    narrow.minWindowVoxels = 1;
    narrow.maxWindowVoxels = 3000;
    StreamOptions wide = narrow;
    wide.maxWindowVoxels = size_t(1) << 30;

    struct Window { size_t voxels; int64_t slabs; };
    // Every voxel tagged with its slab; and no slab may be split between two windows (the
    // compositor flushes a slab's points when its window ends).
    using Tagged = std::tuple<int64_t, float, float, float>;
    const auto run = [&](const StreamOptions& o, std::vector<Window>& windows) {
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch;
        std::vector<Tagged> voxels;
        std::map<int64_t, size_t> windowOfSlab;
        size_t largest = 0;
        while (stream.next(batch)) {
            windows.push_back({batch.size(), batch.slabEnd - batch.slabBegin});
            largest = std::max(largest, batch.size());
            for (size_t i = 0; i < batch.size(); ++i) {
                const int64_t slab = int64_t(std::floor(batch.distance[i] / stream.slabLength()));
                const auto [it, fresh] = windowOfSlab.try_emplace(slab, windows.size());
                EXPECT_EQ(it->second, windows.size()) << "slab " << slab << " split between windows";
                const glm::vec3 p = batch.viewPos[i];
                voxels.emplace_back(slab, p.x, p.y, p.z);
            }
        }
        EXPECT_EQ(stream.largestWindow(), largest);
        EXPECT_EQ(stream.windows(), windows.size());
        std::sort(voxels.begin(), voxels.end());
        return voxels;
    };
    std::vector<Window> n, w;
    EXPECT_EQ(run(narrow, n), run(wide, w));  // the same voxels in the same slabs
    const auto largest = [](const std::vector<Window>& ws) {
        size_t m = 0;
        for (const Window& x : ws) m = std::max(m, x.voxels);
        return m;
    };
    EXPECT_GT(n.size(), 2 * w.size());
    EXPECT_LT(largest(n), largest(w) / 2);
    int narrowed = 0;
    for (size_t k = 0; k + 1 < n.size(); ++k)
        if (n[k].voxels > narrow.maxWindowVoxels && n[k].slabs > 1) {
            EXPECT_EQ(n[k + 1].slabs, n[k].slabs / 2) << "window " << k;
            ++narrowed;
        }
    EXPECT_GT(narrowed, 0);
    for (const Window& x : w) EXPECT_EQ(x.slabs, wide.slabsPerWindow);  // never narrowed
}

}  // namespace
}  // namespace vdbsplat

namespace vdbsplat {
namespace {

// Level of detail (DESIGN §8.2) against brute force: each aggregate of a cell of 2^L voxels per
// side carries the cell's mass Σσ, σ-weighted colour, σ-weighted centroid (view space), the
// projected second moment about it (trace/2 of J Σ Jᵀ) beyond a full cell's own (s²·(n² − 1)/12
// per axis; 0 if less) and its voxel count — for a partly active leaf of random values and a
// colour-varying table, at every level (the levels switching at once: lodBlend off).
TEST(Stream, AggregatesMatchBruteForceMoments) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    uint32_t state = 12345;
    const auto rnd = [&] { state = state * 1664525u + 1013904223u; return float(state >> 8) / float(1 << 24); };
    for (int x = 0; x < 8; ++x)
        for (int y = 0; y < 8; ++y)
            for (int z = 0; z < 8; ++z) {
                const float keep = rnd(), value = rnd();
                if (keep < 0.6f) grid->tree().setValueOn(openvdb::Coord(16 + x, 8 + y, z), value);
            }
    const Volume v = makeVolume(grid, "leaf");
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float t = float(i) / float(ClassificationTable::kSize - 1);
        entries[size_t(i)] = {glm::vec3(t, 1.f - t, 0.25f + 0.5f * t * t), 0.05f + t};
    }
    const ClassificationTable table(entries, 0.f, 1.f);
    const Camera camera({-300.0, -200.0, 500.0}, {20.0, 12.0, 4.0}, {0.0, 0.0, 1.0}, 30.0, 64, 64);
    const glm::dvec3 centre = camera.toView(glm::dvec3(v.indexToWorld * glm::dvec4(20.0, 12.0, 4.0, 1.0)));
    const double spacing = v.voxelSize * camera.focal() / centre.z;  // ≈ projected voxel spacing (px)
    for (int run = 0; run < 6; ++run) {
        const int level = 1 + run / 2, side = 1 << level;  // every level twice: vectorised sums, scalar sums
        StreamOptions o;
        o.vectorLeafMoments = run % 2 == 0;
        o.lodBlend = LodBlend::Off;
        o.pointBelowPx = INFINITY;
        o.lodCellPx = (side + 0.5) * spacing * 1.02;  // admits 2^level, not 2^(level+1)
        o.pointPrefilterVariance = 1.0;
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch, all;
        while (stream.next(batch))
            for (size_t i = 0; i < batch.size(); ++i) {
                all.viewPos.push_back(batch.viewPos[i]), all.sigma.push_back(batch.sigma[i]);
                all.color.push_back(batch.color[i]), all.spread.push_back(batch.spread[i]);
                all.members.push_back(batch.members[i]);
            }
        // Brute force, in double, per cell.
        struct Cell { double m = 0; glm::dvec3 e{0.0}, p{0.0}; glm::dmat3 pp{0.0}; uint32_t n = 0; };
        std::map<std::tuple<int, int, int>, Cell> cells;
        for (auto it = grid->tree().cbeginValueOn(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            const Classified k = table(*it);
            const glm::dvec3 p = camera.toView(glm::dvec3(v.indexToWorld * glm::dvec4(c.x(), c.y(), c.z(), 1.0)));
            Cell& cell = cells[{c.x() >> level, c.y() >> level, c.z() >> level}];
            cell.m += k.sigma, cell.e += double(k.sigma) * glm::dvec3(k.color), cell.p += double(k.sigma) * p;
            cell.pp += double(k.sigma) * glm::outerProduct(p, p);
            ++cell.n;
        }
        ASSERT_EQ(all.viewPos.size(), cells.size()) << "level " << level;
        for (const auto& [key, cell] : cells) {
            const glm::dvec3 mu = cell.p / cell.m;
            size_t best = 0;
            for (size_t i = 1; i < all.viewPos.size(); ++i)
                if (glm::length(glm::dvec3(all.viewPos[i]) - mu) < glm::length(glm::dvec3(all.viewPos[best]) - mu)) best = i;
            SCOPED_TRACE("level " + std::to_string(level) + (o.vectorLeafMoments ? " (vectorised)" : ""));
            EXPECT_LT(glm::length(glm::dvec3(all.viewPos[best]) - mu), 1e-3 * v.voxelSize);
            EXPECT_NEAR(all.sigma[best], cell.m, 1e-5 * cell.m);
            EXPECT_EQ(all.members[best], cell.n);
            const glm::dvec3 color = cell.e / cell.m;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(all.color[best][c], color[c], 1e-5);
            const glm::dmat3 cov = cell.pp / cell.m - glm::outerProduct(mu, mu);
            const double f = camera.focal();
            const glm::dvec3 jx(f / mu.z, 0.0, -f * mu.x / (mu.z * mu.z)), jy(0.0, f / mu.z, -f * mu.y / (mu.z * mu.z));
            const double full = (side * side - 1.0) / 12.0 * v.voxelSize * v.voxelSize;  // a full cell, per axis
            const double spread = std::max(0.0, 0.5 * (glm::dot(jx, cov * jx) + glm::dot(jy, cov * jy)) -
                                                     0.5 * full * (glm::dot(jx, jx) + glm::dot(jy, jy)));
            EXPECT_NEAR(all.spread[best], spread, 2e-3 * 0.5 * full * (glm::dot(jx, jx) + glm::dot(jy, jy)) + 1e-9);
        }
    }
}

// Windows are sized by the records their blocks give, not by their voxels: at a far view, where
// the level of detail draws a block as a few cells, a window takes many more blocks (up to 512),
// so the cloud's 200 000 voxels (4 854 records) come in three windows instead of six of a few
// hundred records each (a dozen parallel passes each, for little work). The records are the
// same whatever the windows (ImagesDoNotDependOnThreadCountOrWindowSize renders it).
TEST(Stream, FarWindowsAreSizedByRecords) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 256, 8.0);
    const ClassificationTable table = constantTable(0.05f);
    StreamOptions o;
    o.pointBelowPx = 1.0;
    o.lodCellPx = 1.25;
    VoxelStream stream(v, camera, table, o);
    VoxelBatch batch;
    size_t windows = 0, records = 0;
    uint64_t members = 0;
    while (stream.next(batch)) {
        ++windows, records += batch.size();
        for (size_t i = 0; i < batch.size(); ++i) members += batch.members[i];
    }
    EXPECT_EQ(members, v.activeVoxels - stream.culledVoxels());  // every voxel, at some level
    EXPECT_LT(records, v.activeVoxels / 8);                      // mostly aggregates
    EXPECT_LE(windows, 3u) << records << " records";  // by voxels: 6
}

// Kept level-of-detail moments (StreamOptions::keepMoments, LodMomentCache): a second render with
// the same buffers reads the moments its first one kept, and gives the same records bit for bit
// as a stream that keeps none; the slots are really read (spoiled, the records change); and
// another transfer function empties them (the records are that table's, not the spoiled slots').
namespace {
struct Records {
    std::vector<float> values;  // every record's fields in order
    bool operator==(const Records&) const = default;
};
Records streamRecords(const Volume& v, const Camera& camera, const ClassificationTable& table, StreamBuffers* kept) {
    StreamOptions o;
    o.pointBelowPx = 1.0;
    o.lodCellPx = 1.25;
    o.keepMoments = kept != nullptr;
    VoxelStream stream(v, camera, table, o, nullptr, nullptr, kept);
    VoxelBatch batch;
    Records r;
    while (stream.next(batch))
        for (size_t i = 0; i < batch.size(); ++i)
            r.values.insert(r.values.end(), {batch.viewPos[i].x, batch.viewPos[i].y, batch.viewPos[i].z, batch.sigma[i],
                                             batch.color[i].x, batch.color[i].y, batch.color[i].z, batch.spread[i],
                                             float(batch.members[i])});
    return r;
}
/// Every field of every record the stream releases, window by window (the depth spreads where kept).
std::vector<float> everyRecord(VoxelStream& stream) {
    VoxelBatch batch;
    std::vector<float> r;
    while (stream.next(batch))
        for (size_t i = 0; i < batch.size(); ++i) {
            r.insert(r.end(), {batch.viewPos[i].x, batch.viewPos[i].y, batch.viewPos[i].z, batch.distance[i], batch.sigma[i],
                               batch.color[i].x, batch.color[i].y, batch.color[i].z, batch.spread[i], float(batch.members[i])});
            if (batch.withDepthSpread) r.push_back(batch.depthSpread[i]);
        }
    return r;
}
ClassificationTable rampTable(float slope) {
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float t = float(i) / float(ClassificationTable::kSize - 1);
        entries[size_t(i)] = {glm::vec3(t, 1.f - t, 0.5f), t < 0.2f ? 0.f : slope * t};
    }
    return ClassificationTable(entries, 0.f, 1.f);
}
}  // namespace

TEST(Stream, KeptMomentsAreReadAndFollowTheTable) {
    const Volume& v = cloud();
    const ClassificationTable a = rampTable(0.3f), b = rampTable(0.7f);
    StreamBuffers kept;
    for (const double distance : {8.0, 3.0}) {  // 4³ and 8³ cells, then 2³ cells blended
        SCOPED_TRACE("distance " + std::to_string(distance));
        const Camera camera = framedCamera(v, 256, distance);
        const Records fresh = streamRecords(v, camera, a, nullptr);
        size_t aggregates = 0;
        for (size_t i = 8; i < fresh.values.size(); i += 9) aggregates += fresh.values[i] > 1.f ? 1 : 0;
        ASSERT_GT(aggregates, 100u);  // level of detail at work
        EXPECT_EQ(streamRecords(v, camera, a, &kept), fresh);  // fills the slots (or reads them)
        EXPECT_EQ(streamRecords(v, camera, a, &kept), fresh);  // reads them
    }
    size_t filled = 0;
    for (int level = 0; level < 3; ++level)
        for (uint8_t h : kept.moments.have[level]) filled += h;
    ASSERT_GT(filled, 100u);
    for (int level = 0; level < 3; ++level) {  // the cells claimed (packed: those with mass only)
        const size_t claimed = kept.moments.cursor[size_t(level)].load();
        ASSERT_LE(claimed, kept.moments.cells[level].size());
        for (size_t i = 0; i < claimed; ++i) {
            CellMoments& c = kept.moments.cells[level][i];
            EXPECT_TRUE(c.m > 0.f || c.n != 0);        // no empty cell is kept
            c.m *= 2.f, c.emission *= 2.f;             // spoiled: twice the mass
        }
    }
    const Camera far = framedCamera(v, 256, 8.0);
    EXPECT_NE(streamRecords(v, far, a, &kept), streamRecords(v, far, a, nullptr));
    EXPECT_EQ(streamRecords(v, far, b, &kept), streamRecords(v, far, b, nullptr));  // another table: emptied
    EXPECT_EQ(streamRecords(v, far, b, &kept), streamRecords(v, far, b, nullptr));
    // b's entries with linear pieces (one, σ = 0.5 everywhere): classified by the pieces, so emptied too.
    LinearPieces flat;
    flat.count = 1;
    flat.value[3][0] = 0.5f;
    const ClassificationTable c(std::vector<Classified>(b.entries(), b.entries() + ClassificationTable::kSize), 0.f, 1.f, flat);
    EXPECT_EQ(streamRecords(v, far, c, &kept), streamRecords(v, far, c, nullptr));
}

// Blended levels (StreamOptions::lodBlend): along a zoom through every level change the leaves
// are drawn at two neighbouring levels with their optical depth split between them, so the
// records' total mass Σσ is the voxels' at every camera (energy, DESIGN §8.2) and each voxel is
// counted once (members); and the passages are really crossed (record counts that are neither
// the lower level's nor the upper's).
// The level-of-detail cells' records through the vectorised form equal the one-cell-at-a-time
// oracle (StreamOptions::vectorCells), record for record, at views of 8³, 4³ and blended 2³ cells,
// with the depth spreads the slab order reads.
TEST(Stream, VectorCellRecordsEqualTheOracle) {
    const Volume& v = cloud();
    const ClassificationTable table = rampTable(0.3f);
    for (const double distance : {8.0, 3.0}) {
        SCOPED_TRACE("distance " + std::to_string(distance));
        const Camera camera = framedCamera(v, 256, distance);
        std::vector<std::vector<float>> runs;
        uint64_t aggregates = 0;
        for (const bool vector : {true, false}) {
            StreamOptions o;
            o.pointBelowPx = 1.0;
            o.lodCellPx = 1.25;
            o.depthSpread = true;
            o.vectorCells = vector;
            VoxelStream stream(v, camera, table, o);
            runs.push_back(everyRecord(stream));
            aggregates = stream.counts().aggregates;
        }
        ASSERT_GT(aggregates, 500u);  // level of detail at work
        EXPECT_EQ(runs[0], runs[1]);
    }
}

TEST(Stream, BlendedLevelsKeepTheEnergy) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    uint32_t state = 777;
    const auto rnd = [&] { state = state * 1664525u + 1013904223u; return float(state >> 8) / float(1 << 24); };
    for (int x = 0; x < 16; ++x)  // 8 leaves, partly active
        for (int y = 0; y < 16; ++y)
            for (int z = 0; z < 16; ++z)
                if (rnd() < 0.7f) grid->tree().setValueOn(openvdb::Coord(x, y, z), rnd());
    const Volume v = makeVolume(grid, "leaves");
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float t = float(i) / float(ClassificationTable::kSize - 1);
        entries[size_t(i)] = {glm::vec3(t, 1.f - t, 0.5f), 0.05f + t};
    }
    const ClassificationTable table(entries, 0.f, 1.f);
    double voxelMass = 0.0;
    uint64_t voxelCount = 0;
    for (auto it = grid->tree().cbeginValueOn(); it; ++it) voxelMass += table(*it).sigma, ++voxelCount;
    struct Drawn { double mass = 0.0; uint64_t members = 0, records = 0; };
    const auto draw = [&](double distance, LodBlend blend) {
        const Camera camera({-300.0 * distance, -200.0 * distance, 500.0 * distance}, {8.0, 8.0, 8.0}, {0.0, 0.0, 1.0},
                            30.0, 64, 64);
        StreamOptions o;
        o.pointBelowPx = INFINITY;
        o.lodCellPx = 1.25;
        o.pointPrefilterVariance = 0.1;
        o.lodBlend = blend;
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch;
        Drawn d;
        while (stream.next(batch))
            for (size_t i = 0; i < batch.size(); ++i) d.mass += batch.sigma[i], d.members += batch.members[i], ++d.records;
        return d;
    };
    // Voxel spacing from ≈ 0.8 px (no aggregate) to ≈ 0.02 px (8³ cells): every passage.
    int passing = 0, stillSwitched = 0, stillBlended = 0;
    for (double distance = 0.12; distance < 6.0; distance *= 1.12) {  // ~10 views inside passages
        const Drawn d = draw(distance, LodBlend::On);
        EXPECT_NEAR(d.mass / voxelMass, 1.0, 2e-5) << "distance " << distance;
        EXPECT_EQ(d.members, voxelCount) << "distance " << distance;
        const Drawn lo = draw(distance, LodBlend::Off), hi = draw(distance * 2.0, LodBlend::Off);
        // LodBlend::Still: the first passage switched (a block draws what Off draws), the later
        // ones blended (what On draws); the energy and the voxel count kept either way.
        const Drawn still = draw(distance, LodBlend::Still);
        EXPECT_NEAR(still.mass / voxelMass, 1.0, 2e-5) << "distance " << distance;
        EXPECT_EQ(still.members, voxelCount) << "distance " << distance;
        EXPECT_LE(still.records, d.records) << "distance " << distance;
        if (still.records == lo.records && still.records < d.records) ++stillSwitched;
        if (still.records == d.records && still.records > lo.records) ++stillBlended;
        if (d.records != lo.records && d.records != hi.records) ++passing;
        // Past the first passage (ℓ ≥ 1.75: the switching rule aggregates at ℓ − 0.75 already),
        // blending costs at most the switching rule's records plus its lighter level's (an eighth
        // on this dense grid; a rule whose 2³ → 4³ passage ran past ℓ = 2 drew 9× there).
        const Drawn before = draw(distance * std::exp2(-(kLodPassage[0].second - kLodPassage[0].first)), LodBlend::Off);
        if (before.records * 4 <= voxelCount) {
            EXPECT_LE(double(d.records), 1.25 * double(lo.records)) << "distance " << distance;
        }
        std::printf("  distance %.3f: %llu records (switching: %llu, and %llu at twice the distance)\n", distance,
                    (unsigned long long)d.records, (unsigned long long)lo.records, (unsigned long long)hi.records);
    }
    EXPECT_GE(passing, 8);
    EXPECT_GE(stillSwitched, 2);  // views in the first passage
    EXPECT_GE(stillBlended, 2);   // views in a later one
}

}  // namespace
}  // namespace vdbsplat

#include <hwy/targets.h>

#include "shading/shading_field.h"
#include "volume/leaf_extract.h"
#include "volume/leaf_moments.h"

namespace vdbsplat {
namespace {

// The vectorised whole-leaf sums against the same sums in double, one voxel at a time: a
// partly active leaf (mask words), a dense one (no mask), values outside the table's range,
// NaN and infinity (σ = 0, not counted), and a colour-varying table.
void expectLeafMomentsMatchTheSums(const ClassificationTable& table, bool shaded = false);

/// Runs @p body on the widest target this CPU has, and again on AVX2 (8 lanes: one row per
/// vector, lane pairs of 4 doubles) where the CPU has wider ones, so that both row layouts of the
/// whole-leaf passes are tested here; @p supported says whether the pass runs on a target.
template <class Supported, class Body>
void onBestAndAvx2(Supported supported, Body body) {
    if (!supported()) GTEST_SKIP() << "this CPU's vectors do not hold whole 8-voxel rows (scalar path only)";
    {
        SCOPED_TRACE("best target");
        body();
    }
#if HWY_ARCH_X86
    if ((hwy::SupportedTargets() & HWY_AVX2) && hwy::SupportedTargets() != HWY_AVX2) {
        hwy::SetSupportedTargetsForTest(HWY_AVX2);
        ASSERT_TRUE(supported());
        SCOPED_TRACE("AVX2");
        body();
        hwy::SetSupportedTargetsForTest(0);  // back to what the CPU has
    }
#endif
}

/// A ramp over the classification table (values mapped from [−0.5, 2]): colour (t, 1 − t,
/// 0.3 + 0.4t²), σ = 0 below @p clearBelow, else 0.02 + 2t.
ClassificationTable leafTestTable(float clearBelow) {
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float t = float(i) / float(ClassificationTable::kSize - 1);
        entries[size_t(i)] = {glm::vec3(t, 1.f - t, 0.3f + 0.4f * t * t), t < clearBelow ? 0.f : 0.02f + 2.f * t};
    }
    return ClassificationTable(entries, -0.5f, 2.f);
}

/// A transfer function of 13 linear pieces over values in [−0.5, 2] (more than one vector of 8
/// lanes holds), three knots inside one bucket of LinearPieces (the compares after the permute),
/// steps in colour and σ, σ = 0 below x = 0.15: the vector passes' classification by pieces.
ClassificationTable piecesTestTable() {
    const auto tf = TransferFunction::fromPoints(
        "pieces",
        {{0.f, glm::vec3(0.1f, 0.9f, 0.2f)}, {0.3f, glm::vec3(0.8f, 0.1f, 0.3f)}, {0.31f, glm::vec3(0.2f)},
         {0.5f, glm::vec3(0.2f)}, {0.5f, glm::vec3(1.f, 0.5f, 0.f)}, {0.9f, glm::vec3(0.f, 0.3f, 1.f)}},
        {{0.15f, 0.f}, {0.2f, 0.4f}, {0.305f, 0.1f}, {0.32f, 1.5f}, {0.45f, 0.2f}, {0.6f, 0.3f}, {0.6f, 0.9f},
         {0.7f, 0.05f}, {0.8f, 2.f}, {0.85f, 0.f}, {0.95f, 0.6f}, {1.f, 0.6f}});
    return tf.bake(-0.5f, 2.f, 1.0);
}

/// One random 8³ leaf: values in [−1, 3), a NaN and an @p infinity at places that move with
/// @p trial, each voxel active with probability @p activeShare (the mask words); @p state is the
/// generator's, carried from leaf to leaf.
struct RandomLeaf {
    std::array<float, 512> values;
    std::array<uint64_t, 8> words{};
};
RandomLeaf randomLeaf(int trial, uint32_t& state, float infinity, float activeShare) {
    const auto rnd = [&] { state = state * 1664525u + 1013904223u; return float(state >> 8) / float(1 << 24); };
    RandomLeaf leaf;
    for (int n = 0; n < 512; ++n) {
        leaf.values[size_t(n)] = -1.f + 4.f * rnd();
        if (n % 97 == trial % 97) leaf.values[size_t(n)] = std::numeric_limits<float>::quiet_NaN();
        if (n % 89 == trial % 89) leaf.values[size_t(n)] = infinity;
        if (rnd() < activeShare) leaf.words[size_t(n >> 6)] |= uint64_t(1) << (n & 63);
    }
    return leaf;
}

/// Shading factors for a leaf's voxels: D in [0.2, 1.4], S in [0, 0.3], G in [0, 1] with some
/// G exactly 0 and one NaN (as a NaN neighbour makes it).
LeafFactors randomFactors(int trial) {
    uint32_t state = 7u + uint32_t(trial);
    const auto rnd = [&] { state = state * 1664525u + 1013904223u; return float(state >> 8) / float(1 << 24); };
    LeafFactors f;
    for (int n = 0; n < LeafFactors::kVoxels; ++n) {
        f.diffuse[n] = 0.2f + 1.2f * rnd(), f.specular[n] = 0.3f * rnd(), f.opacity[n] = rnd();
        if (n % 11 == trial % 11) f.opacity[n] = 0.f;
    }
    f.opacity[(trial * 37) % 512] = std::numeric_limits<float>::quiet_NaN();
    return f;
}

/// A voxel's classification shaded as the stream's voxel-by-voxel path does (VoxelClassifier:
/// applyShading where σ > 0); @p factors nullptr: as it is.
Classified shadedAs(const Classified& c, const LeafFactors* factors, int n) {
    if (!factors || !(c.sigma > 0.f)) return c;
    return applyShading(c, openvdb::Vec3f(factors->diffuse[n], factors->specular[n], factors->opacity[n]));
}

TEST(LeafMoments, MatchTheSumsVoxelByVoxel) {
    onBestAndAvx2(leafMomentsSupported, [] { expectLeafMomentsMatchTheSums(leafTestTable(0.1f)); });
}

// With shading's factors (shading/shade_leaf.h): each voxel c·D + S and σ·G, as applyShading, with
// factors that zero some σ and make one NaN (a non-finite neighbour's gradient: not drawn).
TEST(LeafMoments, MatchTheShadedSums) {
    onBestAndAvx2(leafMomentsSupported, [] { expectLeafMomentsMatchTheSums(leafTestTable(0.1f), true); });
}

TEST(LeafMoments, MatchTheSumsThroughLinearPieces) {
    const ClassificationTable table = piecesTestTable();
    ASSERT_GT(table.pieces().count, 8);
    ASSERT_GE(table.pieces().knotsPerBucket, 2);
    onBestAndAvx2(leafMomentsSupported, [&] { expectLeafMomentsMatchTheSums(table); });
}

void expectLeafMomentsMatchTheSums(const ClassificationTable& table, bool shaded) {
    uint32_t state = 99;
    for (int trial = 0; trial < 40; ++trial) {
        const auto [values, words] = randomLeaf(trial, state, -std::numeric_limits<float>::infinity(), 0.7f);
        const bool dense = trial % 4 == 0;
        const int level = 1 + trial % 3, side = 1 << level, cells = 8 >> level;
        const float half = 0.5f * float(side - 1);
        const LeafFactors factors = randomFactors(trial);
        std::array<CellMoments, 64> got;
        leafMoments(values.data(), dense ? nullptr : words.data(), table, level, got.data(), shaded ? &factors : nullptr);
        struct Sums { double m = 0, e[3] = {}, f[3] = {}, s2[6] = {}; uint32_t count = 0; };
        std::array<Sums, 64> want{};
        for (int n = 0; n < 512; ++n) {
            if (!dense && !(words[size_t(n >> 6)] >> (n & 63) & 1)) continue;
            const Classified c = shadedAs(table(values[size_t(n)]), shaded ? &factors : nullptr, n);
            if (!(c.sigma > 0.f)) continue;
            const int x = n >> 6, y = (n >> 3) & 7, z = n & 7;
            Sums& w = want[size_t(((x >> level) * cells + (y >> level)) * cells + (z >> level))];
            const double d[3] = {(x & (side - 1)) - half, (y & (side - 1)) - half, (z & (side - 1)) - half}, s = c.sigma;
            w.m += s, ++w.count;
            for (int k = 0; k < 3; ++k) w.e[k] += s * c.color[k], w.f[k] += s * d[k];
            w.s2[0] += s * d[0] * d[0], w.s2[1] += s * d[1] * d[1], w.s2[2] += s * d[2] * d[2];
            w.s2[3] += s * d[0] * d[1], w.s2[4] += s * d[0] * d[2], w.s2[5] += s * d[1] * d[2];
        }
        uint32_t total = 0;
        for (int cell = 0; cell < cells * cells * cells; ++cell) {
            SCOPED_TRACE("trial " + std::to_string(trial) + ", level " + std::to_string(level) + ", cell " + std::to_string(cell));
            const Sums& w = want[size_t(cell)];
            const CellMoments& g = got[size_t(cell)];
            total += w.count;
            EXPECT_EQ(g.n, w.count);
            const double tol = 1e-6 * w.m * 16.0 + 1e-7;  // float sums of ≤ 512 terms, |offsets| ≤ 3.5
            EXPECT_NEAR(g.m, w.m, 1e-6 * w.m + 1e-7);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.emission[k], w.e[k], 1e-6 * w.m + 1e-7) << k;
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.first[k], w.f[k], tol) << k;
            const float g2[6] = {g.xx, g.yy, g.zz, g.xy, g.xz, g.yz};
            for (int k = 0; k < 6; ++k) EXPECT_NEAR(g2[k], w.s2[k], tol) << k;
        }
        ASSERT_GT(total, 100u);
    }
}

// The vectorised leaf extraction writes what the voxel-by-voxel path computes, bit for bit and in
// the same order: each active voxel with σ > 0 (not NaN or infinite, not transparent under the
// table, not masked off), its view position and distance in glm's double order rounded to
// float, σ and colour as ClassificationTable::operator(). Partly active and dense leaves, a
// camera off every axis; on the widest target and on AVX2 (one row per vector) where wider exist.
void expectLeafExtractionMatchesTheVoxels(const ClassificationTable& table, bool shaded = false);

TEST(LeafExtract, EqualsTheVoxelByVoxelRecords) {
    onBestAndAvx2(leafExtractSupported, [] { expectLeafExtractionMatchesTheVoxels(leafTestTable(0.3f)); });
}

// Shaded by a leaf's factors (c·D + S, σ·G, then the σ > 0 test), bit for bit.
TEST(LeafExtract, EqualsTheShadedVoxelByVoxelRecords) {
    onBestAndAvx2(leafExtractSupported, [] { expectLeafExtractionMatchesTheVoxels(leafTestTable(0.3f), true); });
}

// The same through a table's linear pieces: σ and colour equal LinearPieces::operator() bit for
// bit, with many pieces and with one (grey's line, broadcast instead of permuted).
TEST(LeafExtract, EqualsTheVoxelByVoxelRecordsThroughLinearPieces) {
    const ClassificationTable table = piecesTestTable();
    ASSERT_GT(table.pieces().count, 8);
    onBestAndAvx2(leafExtractSupported, [&] { expectLeafExtractionMatchesTheVoxels(table); });
    const ClassificationTable line = TransferFunction::fromPoints("line", {{0.f, glm::vec3(0.9f, 0.2f, 0.f)}, {1.f, glm::vec3(0.1f, 0.6f, 1.f)}},
                                                                  {{0.f, 0.f}, {1.f, 0.7f}})
                                         .bake(-0.5f, 2.f, 1.0);
    ASSERT_EQ(line.pieces().count, 1);
    onBestAndAvx2(leafExtractSupported, [&] { expectLeafExtractionMatchesTheVoxels(line); });
}

// In the stream: the same records, window by window, with the vectorised extraction as with the
// voxel-by-voxel path (StreamOptions::vectorExtract), at a framed view where every block is voxels.
TEST(LeafExtract, StreamRecordsEqualTheVoxelByVoxelPath) {
    if (!leafExtractSupported()) GTEST_SKIP() << "this CPU's vectors do not hold whole 8-voxel rows (scalar path only)";
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 256, 1.0);
    const ClassificationTable table = constantTable(0.05f);
    std::vector<std::vector<float>> runs;
    for (const bool vector : {true, false}) {
        StreamOptions o;
        o.vectorExtract = vector;
        VoxelStream stream(v, camera, table, o);
        runs.push_back(everyRecord(stream));
    }
    ASSERT_GT(runs[0].size(), 10 * size_t(100000));
    EXPECT_EQ(runs[0], runs[1]);
}

void expectLeafExtractionMatchesTheVoxels(const ClassificationTable& table, bool shaded) {
    // An index-to-view transform off every axis, with a translation and an uneven scale (as
    // VoxelStream's worldToView · indexToWorld; any affine map).
    glm::dmat4 indexToView(1.0);
    const double m[12] = {0.61, -0.33, 0.72, 0.29, 0.93, 0.17, -0.74, 0.13, 0.66, 0.37 * 3.1, -12.7, 583.3};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) indexToView[c][r] = m[c * 3 + r] * (0.37 + 0.01 * c);
    indexToView[3] = glm::dvec4(m[9], m[10], m[11], 1.0);
    uint32_t state = 5;
    size_t kept = 0;
    for (int trial = 0; trial < 40; ++trial) {
        auto [values, words] = randomLeaf(trial, state, std::numeric_limits<float>::infinity(), 0.6f);
        if (trial % 5 == 1) std::fill(values.begin(), values.begin() + 192, 0.1f);  // transparent rows
        const bool dense = trial % 4 == 0;
        const glm::ivec3 origin(8 * (trial % 3) - 8, 8 * (trial % 5), -16 + 8 * (trial % 7));
        std::vector<glm::vec3> pos(512), color(512);
        std::vector<float> distance(512), sigma(512);
        const LeafFactors factors = randomFactors(trial);
        const size_t n = extractLeafVoxels(values.data(), dense ? nullptr : words.data(), table, indexToView, origin,
                                           LeafRecords{pos.data(), distance.data(), sigma.data(), color.data()},
                                           shaded ? &factors : nullptr);
        size_t k = 0;
        for (int i = 0; i < 512; ++i) {
            if (!dense && !(words[size_t(i >> 6)] >> (i & 63) & 1)) continue;
            const Classified c = shadedAs(table(values[size_t(i)]), shaded ? &factors : nullptr, i);
            if (!(c.sigma > 0.f)) continue;
            SCOPED_TRACE("trial " + std::to_string(trial) + ", voxel " + std::to_string(i));
            ASSERT_LT(k, n);
            const glm::dvec3 v = indexToView * glm::dvec4(glm::dvec3(origin) + glm::dvec3(i >> 6, (i >> 3) & 7, i & 7), 1.0);
            EXPECT_EQ(pos[k], glm::vec3(v));
            EXPECT_EQ(distance[k], float(glm::length(v)));
            EXPECT_EQ(sigma[k], c.sigma);
            EXPECT_EQ(color[k], c.color);
            ++k;
        }
        EXPECT_EQ(n, k);
        kept += k;
    }
    EXPECT_GT(kept, 3000u);
}

// Octant culling (StreamOptions::octantCulling): with the left half of the image finished, a leaf
// whose rectangle straddles the edge keeps only its octants that reach the right half. The
// records are those of the stream without it, in order, less some whose voxels lie left of the
// edge; each voxel left out is counted as occluded, and some are left out.
TEST(Stream, HiddenOctantsAreNeitherExtractedNorReleased) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 256, 1.0);
    const ClassificationTable table = constantTable(0.05f);  // every active voxel gives a record
    const int edge = 128;
    const auto hidden = [&](int, int, int x1, int) { return x1 < edge; };
    const auto partlyHidden = [&](int x0, int, int, int) { return x0 < edge; };
    struct Run {
        std::vector<std::array<float, 4>> records;  // view position, σ
        uint64_t occluded = 0;
    };
    std::vector<Run> runs;
    for (const bool octants : {false, true}) {
        StreamOptions o;
        o.octantCulling = octants;
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch;
        Run run;
        while (stream.next(batch, hidden, partlyHidden))
            for (size_t i = 0; i < batch.size(); ++i)
                run.records.push_back({batch.viewPos[i].x, batch.viewPos[i].y, batch.viewPos[i].z, batch.sigma[i]});
        run.occluded = stream.counts().occluded;
        runs.push_back(std::move(run));
    }
    const Run &all = runs[0], &culled = runs[1];
    size_t j = 0, left = 0;
    for (const auto& r : all.records) {
        if (j < culled.records.size() && culled.records[j] == r) {
            ++j;
            continue;
        }
        ++left;
        const PixelCoord p = camera.project(ViewPoint(glm::dvec3(r[0], r[1], r[2])));
        ASSERT_LT(p.x, double(edge)) << "a voxel right of the edge was culled";
    }
    EXPECT_EQ(j, culled.records.size()) << "the culled stream's records are not the others', in order";
    EXPECT_GT(left, 1000u);
    EXPECT_LT(left, all.records.size() / 2);
    EXPECT_EQ(culled.occluded - all.occluded, left);
}

// A block whose voxels are all points (StreamOptions::pointBelowPx) is tested for occlusion by the
// box of its voxel centres and a point's reach (kPointMaxRadiusPx), not the kernel-widened box a
// splat needs (VoxelStream::screenRect). With the left part of the image finished, every point the
// stream leaves out has all its pixels there (centre + 3 px left of the edge: a point draws the
// pixel centres within 3.5 px of its own), and some lie closer to the edge than the kernel-widened
// box allowed (its 2.5 voxels each side): the test bites on both sides.
TEST(Stream, PointBlocksAreCulledByThePointsReach) {
    const Volume& v = cloud();
    const Camera camera = framedCamera(v, 512, 1.0);
    const ClassificationTable table = constantTable(0.05f);
    const double spacingPx = v.voxelSize * camera.focal() / camera.toView(glm::dvec3(0.0)).z;
    const int edge = 256;
    const auto hidden = [&](int, int, int x1, int) { return x1 < edge; };
    StreamOptions o;
    o.pointBelowPx = 1e9;  // every voxel a point
    o.lodCellPx = 0.0;     // one point per voxel
    std::vector<std::vector<std::array<float, 4>>> runs;
    for (const bool culling : {false, true}) {
        VoxelStream stream(v, camera, table, o);
        VoxelBatch batch;
        std::vector<std::array<float, 4>> records;
        while (culling ? stream.next(batch, hidden) : stream.next(batch))
            for (size_t i = 0; i < batch.size(); ++i)
                records.push_back({batch.viewPos[i].x, batch.viewPos[i].y, batch.viewPos[i].z, batch.sigma[i]});
        std::sort(records.begin(), records.end());
        runs.push_back(std::move(records));
    }
    std::vector<std::array<float, 4>> left;
    std::set_difference(runs[0].begin(), runs[0].end(), runs[1].begin(), runs[1].end(), std::back_inserter(left));
    EXPECT_EQ(runs[0].size() - runs[1].size(), left.size()) << "the culled stream released a record the other did not";
    double rightmost = -INFINITY;
    for (const auto& r : left) {
        const double x = camera.project(ViewPoint(glm::dvec3(r[0], r[1], r[2]))).x;
        ASSERT_LE(x + 3.0, double(edge) + 1e-3) << "a point with a pixel right of the edge was culled";
        rightmost = std::max(rightmost, x);
    }
    EXPECT_GT(left.size(), 1000u);
    // The kernel-widened box culls only points at least 4 px + 2.5 voxels left of the edge.
    EXPECT_GT(rightmost, edge - 4.0 - 2.5 * spacingPx + 0.25) << "spacing " << spacingPx << " px";
}

}  // namespace
}  // namespace vdbsplat
