// tests/bench/bench_leaf_moments.cpp — Google Benchmark of the level-of-detail sums of one 8³ leaf
// (volume/leaf_moments.h): the vectorised sums at each level against the scalar classification
// they replace (the table lookup and the σ, σ·c, σ·d, σ·d² sums voxel by voxel), classifying through
// the table's entries (pieces:0, gathers), through the linear pieces of the ct-bone preset
// (pieces:1, permutes; 10 pieces, values spread over all of them), and through grey's one piece
// (pieces:2). Not a test: run
//   build/bench_leaf_moments            (ns per voxel = the reported time / 512)
#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#include "volume/leaf_moments.h"

namespace {
using namespace vdbsplat;

struct Data {
    ClassificationTable table, pieces, line;
    std::vector<float> values;  // 256 leaves
    Data() : values(512 * 256) {
        std::vector<Classified> e(ClassificationTable::kSize);
        for (int i = 0; i < ClassificationTable::kSize; ++i) {
            const float t = float(i) / float(ClassificationTable::kSize - 1);
            e[size_t(i)] = {glm::vec3(t, 1.f - t, 0.5f), 0.1f + t};
        }
        table = ClassificationTable(e, 0.f, 1.f);
        pieces = TransferFunction::preset("ct-bone").bake(0.f, 1.f, 1.0);
        line = TransferFunction::preset("grey").bake(0.f, 1.f, 1.0);  // one piece
        uint32_t s = 1;
        for (float& x : values) s = s * 1664525u + 1013904223u, x = float(s >> 8) / float(1 << 24);
    }
};
const Data& data() {
    static const Data d;
    return d;
}

void Vectorised(benchmark::State& state) {
    const Data& d = data();
    const int level = int(state.range(0));
    const ClassificationTable& table = state.range(1) == 0 ? d.table : state.range(1) == 1 ? d.pieces : d.line;
    if (!leafMomentsSupported()) state.SkipWithError("no 8- or 16-lane float vectors on this CPU");
    std::array<CellMoments, 64> out;
    size_t leaf = 0;
    for (auto _ : state) {
        leafMoments(d.values.data() + 512 * (leaf++ % 256), nullptr, table, level, out.data());
        benchmark::DoNotOptimize(out);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * 512);
}

void ScalarClassifyAndSum(benchmark::State& state) {
    const Data& d = data();
    size_t leaf = 0;
    for (auto _ : state) {
        const float* v = d.values.data() + 512 * (leaf++ % 256);
        CellMoments m;
        for (int n = 0; n < 512; ++n) {
            const Classified c = d.table(v[n]);
            const glm::vec3 off(float(n >> 6) - 3.5f, float((n >> 3) & 7) - 3.5f, float(n & 7) - 3.5f);
            m.m += c.sigma, m.emission += c.sigma * c.color, m.first += c.sigma * off;
            m.xx += c.sigma * off.x * off.x, m.yy += c.sigma * off.y * off.y, m.zz += c.sigma * off.z * off.z;
            m.xy += c.sigma * off.x * off.y, m.xz += c.sigma * off.x * off.z, m.yz += c.sigma * off.y * off.z;
        }
        benchmark::DoNotOptimize(m);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * 512);
}

BENCHMARK(Vectorised)->ArgNames({"level", "pieces"})->ArgsProduct({{1, 2, 3}, {0, 1, 2}});
BENCHMARK(ScalarClassifyAndSum);
}  // namespace

BENCHMARK_MAIN();
