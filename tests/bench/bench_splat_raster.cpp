// tests/bench/bench_splat_raster.cpp — Google Benchmark of the splat loop over one tile
// (composite/splat_raster.h, drawSplatVector), on 1024 real kernel spheres seen through a 400²
// camera (f ≈ 746 px) at the projected voxel spacings of the standard views: ~1.2 px (the framed
// Engine: supports ~4 px in radius, the two-row box loop) and ~4 px (a close view: ~9 px, the
// row loops), through the table index or the exact index (--footprint auto off the axis), with
// the low-pass widening. Each splat is moved into the benchmark's one tile (the conic and the map
// do not change under a move), its τ small (as a CT's: the short opacity series), and the tile's
// transmittance is restored every iteration, so every pixel stays live. Not a test:
//   build/bench_splat_raster      (ns per splat = the reported time / 1024)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "composite/splat_raster.h"
#include "footprint/ellipse.h"
#include "footprint/kernel.h"
#include "footprint/screen_kernel.h"
#include "footprint/tables.h"

namespace {
using namespace vdbsplat;

constexpr int kSplats = 1024;
constexpr double kFocal = 746.4;  // 400 px, 30° field of view

const Tables& tables() {
    static const Tables t = buildTables();
    return t;
}

/// @p kSplats splats of voxel spacing @p spacingPx (pixels), each clipped to the tile at the origin.
std::vector<SplatRaster> splats(double spacingPx, bool exactIndex, bool apart) {
    std::vector<SplatRaster> out;
    uint32_t state = 7;
    const auto u = [&] { return state = state * 1664525u + 1013904223u, double(state >> 8) / double(1 << 24); };
    const double z = kFocal / spacingPx;  // h = 1
    while (out.size() < size_t(kSplats)) {
        // Anywhere on the 400² image (off the axis as much as the views are), then moved into the tile.
        const glm::dvec3 c((u() - 0.5) * 400.0 * z / kFocal, (u() - 0.5) * 400.0 * z / kFocal, z);
        const SphereProjection sphere = projectSphere(c, Kernel::kRadius, kFocal, {200.0, 200.0});
        if (!sphere.isEllipse()) continue;
        const ScreenKernel k = makeScreenKernel(sphere);
        const double sin2 = sphere.sinAlpha * sphere.sinAlpha;
        if (!exactIndex && !tables().poly.covers(sin2)) continue;
        SplatRaster s;
        // apart: each in the next quarter of the tile, so that no two consecutive splats share a pixel.
        const size_t q = out.size() % 4;
        const glm::dvec2 at = apart ? glm::dvec2(q & 1 ? 24.0 : 8.0, q & 2 ? 24.0 : 8.0) + glm::dvec2(u() - 0.5, u() - 0.5)
                                    : glm::dvec2(4.0 + 24.0 * u(), 4.0 + 24.0 * u());
        const glm::dvec2 move = at - k.centre;
        s.cx = float(k.centre.x + move.x), s.cy = float(k.centre.y + move.y);
        s.qxx = float(k.conic[0][0]), s.qxy = float(k.conic[0][1]), s.qyy = float(k.conic[1][1]);
        s.scale = float(0.02 * k.amplitude);
        s.series = opacitySeriesFor(s.scale * tables().poly.peak());
        s.exactIndex = exactIndex;
        s.coef = exactIndex ? tables().poly.axisRow() : tables().poly.row(sin2);
        s.map = makeExactIndexMap(k, sphere, k.centre);
        s.color = glm::vec3(float(u()), float(u()), float(u()));
        s.epsilon = 1e-4f;
        s.safeT = remainderBound(s.epsilon, s.scale * tables().poly.peak());  // as the compositor sets it
        const PixelRange r = pixelRange(PixelBox{k.bounds.lo + move, k.bounds.hi + move}, kTileSize, kTileSize);
        s.x0 = r.x0, s.y0 = r.y0, s.x1 = r.x1, s.y1 = r.y1;
        if (s.x0 > s.x1 || s.y0 > s.y1) continue;
        out.push_back(s);
    }
    return out;
}

void Splats(benchmark::State& state) {
    const double spacing = state.range(0) / 10.0;
    const std::vector<SplatRaster> list = splats(spacing, state.range(1) != 0, state.range(2) != 0);
    alignas(64) static std::array<float, kTilePixels> T0, T, R, G, B;
    T0.fill(1.f), R.fill(0.f), G.fill(0.f), B.fill(0.f);
    const TileBuffers tile{T.data(), R.data(), G.data(), B.data(), 0, 0};
    for (auto _ : state) {
        T = T0;
        for (const SplatRaster& s : list) drawSplatVector(s, tile);
        benchmark::DoNotOptimize(T.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * kSplats);
}
BENCHMARK(Splats)->ArgNames({"spacing_x10", "exact", "apart"})->ArgsProduct({{12, 40}, {0, 1}, {0, 1}});

}  // namespace

BENCHMARK_MAIN();
