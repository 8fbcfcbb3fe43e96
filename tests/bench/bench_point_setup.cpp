// tests/bench/bench_point_setup.cpp — Google Benchmark of a point's filter set-up (pointfilter/
// point_filter.h): setupPoint (scalar, the oracle) against setupPointVector, on 4096 points with
// the 10⁸-voxel cloud's filter variances (0.6–1 px spacing, the postfilter's low-pass). Not a test:
//   build/bench_point_setup            (ns per point = the reported time / 4096)
#include <benchmark/benchmark.h>

#include <vector>

#include "pointfilter/point_filter.h"
#include "render/postfilter.h"

namespace {
using namespace vdbsplat;

struct Point {
    PixelCoord centre;
    double variance;
};
const std::vector<Point>& points() {
    static const std::vector<Point> p = [] {
        std::vector<Point> out;
        uint32_t s = 1;
        const auto u = [&] { return s = s * 1664525u + 1013904223u, double(s >> 8) / double(1 << 24); };
        for (int i = 0; i < 4096; ++i) {
            const PixelCoord c(float(1900 * u()), float(1060 * u()));  // float centres, as the renderer's
            out.push_back({c, double(float(pointFilterVariance(0.6 + 0.4 * u(), kSubpixelPrefilterVariance)))});
        }
        return out;
    }();
    return p;
}

template <PointSetup (*Setup)(const PixelCoord&, double)>
void Run(benchmark::State& state) {
    for (auto _ : state) {
        float sum = 0.0f;
        for (const Point& p : points()) sum += Setup(p.centre, p.variance).norm;
        benchmark::DoNotOptimize(sum);
    }
}
BENCHMARK(Run<setupPoint>)->Name("Scalar");
BENCHMARK(Run<setupPointVector>)->Name("Vector");

}  // namespace

BENCHMARK_MAIN();
