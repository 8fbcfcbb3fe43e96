// tests/composite/test_compositor.cpp — the tile compositor and the projection stage against
// slow, obvious implementations (../shared/STYLE.md, gsplat: an oracle beside every fast path):
//   - the Highway splat loop against the same maths one pixel at a time;
//   - TileCompositor (binning, sorting, tiles, slab buffers, early termination) against a
//     per-pixel loop over every primitive in (slab, points before splats, depth, index) order;
//   - projectBatch against projectVoxel called voxel by voxel.
#include <gtest/gtest.h>
#include <hwy/highway.h>
#include <hwy/targets.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "composite/compositor.h"
#include "composite/opacity.h"
#include "composite/splat_raster.h"
#include "footprint/kernel.h"
#include "pointfilter/point_filter.h"
#include "render/project.h"
#include "support/projection.h"
#include "support/targets.h"

namespace vdbsplat {
namespace {

const Tables& tables() { return test::sharedTables(); }
Camera testCamera(int size) { return test::boxCamera(size); }

struct TileArrays {
    alignas(64) std::array<float, kTilePixels> T, R, G, B;
    TileBuffers buffers(int x0, int y0) { return {T.data(), R.data(), G.data(), B.data(), x0, y0}; }
};

void vectorLoopMatchesTheScalarLoop();
void nonFiniteConicStaysInsideItsRange();
void shortOpacitySeriesMatchTheGeneralForm();

using test::forEachTarget;

// Random splats over one tile: the vector loop equals the scalar loop to float rounding, for the
// table index and for the exact index, with some pixels already finished (T < ε).
TEST(SplatRaster, VectorLoopMatchesTheScalarLoop) { forEachTarget([] { vectorLoopMatchesTheScalarLoop(); }); }

/// A random splat of a real kernel sphere in front of a 64² camera, possibly off-axis and near
/// (@p exactIndex: the exact index), clipped to the tile under its centre (@p tx0, @p ty0), and
/// random tile pixels with some already finished (T < ε). False when there is nothing to draw.
bool randomSplat(std::mt19937& rng, bool exactIndex, SplatRaster& s, int& tx0, int& ty0, TileArrays& a) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const Camera camera = testCamera(64);
    const glm::dvec3 c((u(rng) - 0.5f) * 6.0, (u(rng) - 0.5f) * 6.0, 6.0 + u(rng) * 30.0);
    const SphereProjection sphere = projectSphere(camera, ViewPoint(c), Kernel::kRadius * (0.2 + u(rng)));
    if (!sphere.isEllipse()) return false;
    const ScreenKernel k = makeScreenKernel(sphere);
    s = SplatRaster{};
    s.cx = float(k.centre.x), s.cy = float(k.centre.y);
    s.qxx = float(k.conic[0][0]), s.qxy = float(k.conic[0][1]), s.qyy = float(k.conic[1][1]);
    s.scale = 0.05f + 3.f * u(rng);
    s.exactIndex = exactIndex;
    const double sin2 = (sphere.r / sphere.D) * (sphere.r / sphere.D);
    if (!s.exactIndex && !tables().poly.covers(sin2)) return false;
    s.coef = s.exactIndex ? tables().poly.axisRow() : tables().poly.row(sin2);
    s.map = makeExactIndexMap(k, sphere, PixelCoord(s.cx, s.cy));
    s.color = glm::vec3(u(rng), u(rng), u(rng));
    s.epsilon = kTransmittanceEpsilon;
    // Half the splats with the compositor's bound below which lanes are checked for a finishing
    // deposit, half with every lane checked: the two must agree with the scalar loop alike.
    if (u(rng) < 0.5f) s.safeT = remainderBound(s.epsilon, s.scale * tables().poly.peak());
    constexpr int kLastTile = 64 / kTileSize - 1;
    tx0 = std::clamp(int(std::floor(s.cx / kTileSize)), 0, kLastTile) * kTileSize;
    ty0 = std::clamp(int(std::floor(s.cy / kTileSize)), 0, kLastTile) * kTileSize;
    const PixelRange r = pixelRange(k.bounds, 64, 64);
    s.x0 = std::max(r.x0, tx0), s.x1 = std::min(r.x1, tx0 + kTileSize - 1);
    s.y0 = std::max(r.y0, ty0), s.y1 = std::min(r.y1, ty0 + kTileSize - 1);
    if (s.x0 > s.x1 || s.y0 > s.y1) return false;
    for (size_t i = 0; i < size_t(kTilePixels); ++i) {
        // Finished pixels, pixels a deposit may finish (T a few ε) and the rest.
        const float kind = u(rng);
        a.T[i] = kind < 0.1f ? 0.5f * kTransmittanceEpsilon : kind < 0.25f ? kTransmittanceEpsilon * (1.f + 4.f * u(rng)) : u(rng);
        a.R[i] = u(rng), a.G[i] = u(rng), a.B[i] = u(rng);
    }
    return true;
}

void vectorLoopMatchesTheScalarLoop() {
    std::mt19937 rng(11);
    double worst = 0.0;
    int drawn = 0, remainders = 0;
    for (int trial = 0; trial < 300; ++trial) {
        SplatRaster s;
        int tx0 = 0, ty0 = 0;
        TileArrays a, b;
        if (!randomSplat(rng, trial % 2 == 1, s, tx0, ty0, a)) continue;
        b = a;
        const TileArrays before = a;
        drawSplatVector(s, a.buffers(tx0, ty0));
        drawSplatScalarPoly(s, b.buffers(tx0, ty0));
        for (size_t i = 0; i < size_t(kTilePixels); ++i) {
            if (b.T[i] != a.T[i] || b.R[i] != a.R[i]) ++drawn;
            worst = std::max({worst, double(std::abs(a.T[i] - b.T[i])), double(std::abs(a.R[i] - b.R[i])),
                              double(std::abs(a.G[i] - b.G[i])), double(std::abs(a.B[i] - b.B[i]))});
            // Finished pixels and pixels outside the range stay exactly as they were.
            const int x = tx0 + int(i % kTileSize), y = ty0 + int(i / kTileSize);
            const bool outside = x < s.x0 || x > s.x1 || y < s.y0 || y > s.y1;
            if (outside || before.T[i] < kTransmittanceEpsilon) {
                ASSERT_EQ(a.T[i], before.T[i]) << "trial " << trial << " pixel " << i;
                ASSERT_EQ(b.T[i], before.T[i]) << "trial " << trial << " pixel " << i;
            }
            // A deposit that finishes a pixel takes its whole remainder, in both loops: C += T·c, T = 0.
            if (before.T[i] >= kTransmittanceEpsilon && (a.T[i] < kTransmittanceEpsilon || b.T[i] < kTransmittanceEpsilon)) {
                ++remainders;
                ASSERT_EQ(a.T[i], 0.f) << "trial " << trial << " pixel " << i;
                ASSERT_EQ(b.T[i], 0.f) << "trial " << trial << " pixel " << i;
                const float expected[3] = {before.R[i] + before.T[i] * s.color.x, before.G[i] + before.T[i] * s.color.y,
                                           before.B[i] + before.T[i] * s.color.z};
                const float got[2][3] = {{a.R[i], a.G[i], a.B[i]}, {b.R[i], b.G[i], b.B[i]}};
                for (const auto& g : got)
                    for (int k = 0; k < 3; ++k) ASSERT_NEAR(g[k], expected[k], 1e-7f) << "trial " << trial << " pixel " << i;
            }
        }
    }
    std::printf("  max |vector − scalar| = %.3g over %d changed values, %d remainders\n", worst, drawn, remainders);
    EXPECT_GT(drawn, 1000);      // the loops did draw
    EXPECT_GT(remainders, 100);  // and finished pixels under splats took their remainders
    EXPECT_LT(worst, 2e-6);
}

// One channel (TileBuffers without G and B, ColorChannels::Grey): the vector loop and the scalar
// loop leave T and R exactly as with all four channels, for the table and the exact index; the
// slab compositing likewise, emptying τ and the red sums and leaving the green and blue ones.
void oneChannelIsTheRedOfThree() {
    std::mt19937 rng(23);
    int drawn = 0;
    for (int trial = 0; trial < 200; ++trial) {
        SplatRaster s;
        int tx0 = 0, ty0 = 0;
        TileArrays a;
        if (!randomSplat(rng, trial % 2 == 1, s, tx0, ty0, a)) continue;
        const TileArrays before = a;
        TileArrays b = a, c = a, d = a;
        drawSplatVector(s, a.buffers(tx0, ty0));
        drawSplatVector(s, {b.T.data(), b.R.data(), nullptr, nullptr, tx0, ty0});
        drawSplatScalarPoly(s, c.buffers(tx0, ty0));
        drawSplatScalarPoly(s, {d.T.data(), d.R.data(), nullptr, nullptr, tx0, ty0});
        ASSERT_EQ(a.T, b.T) << "trial " << trial;
        ASSERT_EQ(a.R, b.R) << "trial " << trial;
        ASSERT_EQ(c.T, d.T) << "trial " << trial;
        ASSERT_EQ(c.R, d.R) << "trial " << trial;
        ASSERT_EQ(b.G, before.G) << "trial " << trial;  // not written
        ASSERT_EQ(d.B, before.B) << "trial " << trial;
        drawn += a.R != before.R;
        // The slab order: two slabs taking fractions of each τ, with and without green and blue sums.
        TileArrays sa[2], sb[2];
        SlabTargets ta, tb;
        ta.count = tb.count = 2;
        for (size_t j = 0; j < 2; ++j) {
            sa[j] = before, sb[j] = before;
            ta.tau[j] = sa[j].T.data(), ta.er[j] = sa[j].R.data(), ta.eg[j] = sa[j].G.data(), ta.eb[j] = sa[j].B.data();
            tb.tau[j] = sb[j].T.data(), tb.er[j] = sb[j].R.data();
            ta.fraction[j] = tb.fraction[j] = 0.3f + 0.4f * float(j);
        }
        for (const bool vector : {true, false}) {
            s.slabs = &ta;
            vector ? drawSplatVector(s, a.buffers(tx0, ty0)) : drawSplatScalarPoly(s, a.buffers(tx0, ty0));
            s.slabs = &tb;
            vector ? drawSplatVector(s, {a.T.data(), a.R.data(), nullptr, nullptr, tx0, ty0})
                   : drawSplatScalarPoly(s, {a.T.data(), a.R.data(), nullptr, nullptr, tx0, ty0});
            for (size_t j = 0; j < 2; ++j) {
                ASSERT_EQ(sa[j].T, sb[j].T) << "trial " << trial << " slab " << j;  // τ sums
                ASSERT_EQ(sa[j].R, sb[j].R) << "trial " << trial << " slab " << j;  // red sums
                ASSERT_EQ(sb[j].G, before.G) << "trial " << trial << " slab " << j;
            }
        }
        s.slabs = nullptr;
    }
    EXPECT_GT(drawn, 50);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int trial = 0; trial < 50; ++trial) {
        TileArrays a, b;
        alignas(64) std::array<float, kTilePixels> tau, er, eg, eb;
        for (size_t i = 0; i < size_t(kTilePixels); ++i) {
            a.T[i] = u(rng) < 0.1f ? 0.5f * kTransmittanceEpsilon : u(rng), a.R[i] = u(rng), a.G[i] = u(rng), a.B[i] = u(rng);
            tau[i] = u(rng) < 0.3f ? 0.f : 3.f * u(rng), er[i] = tau[i] * u(rng), eg[i] = 0.5f + u(rng), eb[i] = 0.5f + u(rng);
        }
        b = a;
        alignas(64) std::array<float, kTilePixels> tauB = tau, erB = er, egB = eg, ebB = eb;  // (aligned loads)
        const auto egBefore = eg;
        const auto Tbefore = a.T;
        const TileRect rect{int(8 * u(rng)), int(8 * u(rng)), 16 + int(15 * u(rng)), 16 + int(15 * u(rng))};
        compositeSlabVector(tau.data(), er.data(), eg.data(), eb.data(), a.buffers(0, 0), kTransmittanceEpsilon, rect);
        compositeSlabVector(tauB.data(), erB.data(), egB.data(), ebB.data(), {b.T.data(), b.R.data(), nullptr, nullptr, 0, 0},
                            kTransmittanceEpsilon, rect);
        ASSERT_EQ(a.T, b.T) << "trial " << trial;
        ASSERT_EQ(a.R, b.R) << "trial " << trial;
        ASSERT_EQ(tau, tauB) << "trial " << trial;  // emptied alike
        ASSERT_EQ(er, erB) << "trial " << trial;
        ASSERT_EQ(egB, egBefore) << "trial " << trial;  // one channel: the green sums left as they were
        ASSERT_NE(eg, egBefore) << "trial " << trial;   // three: emptied over the rectangle
        ASSERT_NE(a.T, Tbefore) << "trial " << trial;   // (the slab was composited)
    }
}
TEST(SplatRaster, OneChannelIsTheRedOfThree) { forEachTarget([] { oneChannelIsTheRedOfThree(); }); }

// The short opacity series (OpacitySeries) a splat takes when every τ it deposits is small give
// the general form's values to float rounding, at the edges of their ranges (τ up to 0.03 and
// 0.2): a range too wide for its series (Degree4 up to 0.2: error 1.3e−5) fails here. The bound
// FootprintPolynomials::peak() covers every row's polynomial.
TEST(SplatRaster, ShortOpacitySeriesMatchTheGeneralForm) { forEachTarget([] { shortOpacitySeriesMatchTheGeneralForm(); }); }

void shortOpacitySeriesMatchTheGeneralForm() {
    EXPECT_EQ(opacitySeriesFor(std::numeric_limits<float>::quiet_NaN()), OpacitySeries::Any);
    EXPECT_EQ(opacitySeriesFor(0.03f), OpacitySeries::Degree4);
    EXPECT_EQ(opacitySeriesFor(0.2f), OpacitySeries::Degree6);
    EXPECT_EQ(opacitySeriesFor(0.21f), OpacitySeries::Any);
    const float peak = tables().poly.peak();
    EXPECT_GE(peak, FootprintPolynomials::evaluate(tables().poly.axisRow(), 0.f));
    EXPECT_LE(peak, 1.01f * float(Kernel::footprint(0.0)));
    std::mt19937 rng(5);
    for (const float tauBound : {0.03f, 0.2f}) {
        double worst = 0.0;
        int drawn = 0;
        for (int trial = 0; trial < 200; ++trial) {
            SplatRaster s;
            int tx0 = 0, ty0 = 0;
            TileArrays a, b;
            if (!randomSplat(rng, trial % 2 == 1, s, tx0, ty0, a)) continue;
            s.scale = 0.9999f * tauBound / peak;  // the largest τ at the range's end
            s.color = glm::vec3(1.f);
            a.T.fill(1.f), a.R.fill(0.f);  // one deposit on a clear tile: R = α
            b = a;
            drawSplatVector(s, b.buffers(tx0, ty0));  // Any: the general form
            s.series = opacitySeriesFor(s.scale * peak);
            EXPECT_NE(s.series, OpacitySeries::Any);
            drawSplatVector(s, a.buffers(tx0, ty0));
            for (size_t i = 0; i < size_t(kTilePixels); ++i) {
                if (!(b.R[i] > 0.f)) continue;
                ++drawn;
                worst = std::max(worst, std::abs(double(a.R[i]) - double(b.R[i])) / double(b.R[i]));
            }
        }
        std::printf("  τ ≤ %.2f: max |α_short − α_general| / α = %.3g over %d pixels\n", tauBound, worst, drawn);
        EXPECT_GT(drawn, 1000);
        EXPECT_LT(worst, 1e-6) << "tau bound " << tauBound;
    }
}

// A splat whose conic or centre is not finite (or degenerate) draws nothing outside its clipped
// range, does not crash and ends: the wide and narrow loops clamp their chords whatever the conic
// (a chord clamped as floats only ran for five minutes here on one target: a NaN's integer
// conversion minus the tile's x wrapped around).
TEST(SplatRaster, NonFiniteConicStaysInsideItsRange) { forEachTarget([] { nonFiniteConicStaysInsideItsRange(); }); }

void nonFiniteConicStaysInsideItsRange() {
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float bad[] = {nan, inf, -inf, 0.f, 1e-30f, 1e30f};
    int cases = 0;
    for (const float v : bad)
        for (int field = 0; field < 5; ++field)
            for (const bool wide : {false, true}) {
                SplatRaster s;
                s.cx = 40.f, s.cy = 40.f;
                s.qxx = 0.01f, s.qxy = 0.f, s.qyy = 0.01f;
                float* f[] = {&s.cx, &s.cy, &s.qxx, &s.qxy, &s.qyy};
                *f[field] = v;
                s.scale = 1.f;
                s.coef = tables().poly.axisRow();
                s.color = glm::vec3(1.f);
                s.epsilon = kTransmittanceEpsilon;
                // A box 20 wide (the wide rows) or 6 wide (the box pairs), inside tile (32, 32).
                s.x0 = 34, s.x1 = wide ? 53 : 39, s.y0 = 35, s.y1 = 50;
                TileArrays a;
                a.T.fill(1.f), a.R.fill(0.f), a.G.fill(0.f), a.B.fill(0.f);
                drawSplatVector(s, a.buffers(32, 32));
                for (size_t i = 0; i < size_t(kTilePixels); ++i) {
                    const int x = 32 + int(i % kTileSize), y = 32 + int(i / kTileSize);
                    if (x < s.x0 || x > s.x1 || y < s.y0 || y > s.y1) {
                        ASSERT_EQ(a.T[i], 1.f) << "value " << v << " field " << field << " pixel " << x << "," << y;
                        ASSERT_EQ(a.R[i], 0.f) << "value " << v << " field " << field << " pixel " << x << "," << y;
                    }
                }
                ++cases;
            }
    EXPECT_EQ(cases, 60);
}

/// The slow compositor: every pixel walks every primitive in the compositor's order
/// (slab, points before splats, depth, index); points of a slab are summed, then composited
/// (DESIGN §4); splats are composited one by one with the table path's deposit. The deposit that
/// leaves T < ε takes the pixel's whole remainder instead (C += T·c, T = 0), and nothing follows.
Image slowComposite(const std::vector<std::vector<Primitive>>& windows, int w, int h) {
    Image image(w, h);
    std::vector<float> T(size_t(w) * h, 1.f);
    std::vector<glm::vec3> C(size_t(w) * h, glm::vec3(0.f));
    const auto over = [&](size_t pix, float tau, const glm::vec3& color) {
        const float a = opacityFromOpticalDepth(tau), after = T[pix] - T[pix] * a;
        if (after < kTransmittanceEpsilon) {  // the deposit that finishes the pixel takes its remainder
            C[pix] += T[pix] * color;
            T[pix] = 0.f;
            return;
        }
        C[pix] += T[pix] * a * color;
        T[pix] = after;
    };
    for (const auto& prims : windows) {
        std::vector<size_t> order(prims.size());
        std::iota(order.begin(), order.end(), 0);
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            const Primitive &p = prims[a], &q = prims[b];
            const int kp = p.kind == PrimitiveKind::Point ? 0 : 1, kq = q.kind == PrimitiveKind::Point ? 0 : 1;
            return std::tie(p.slab, kp, p.depth) < std::tie(q.slab, kq, q.depth);
        });
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t pix = size_t(y) * w + x;
                float slabTau = 0.f;
                glm::vec3 slabEmission(0.f);
                int64_t slabOf = INT64_MIN;
                const auto flush = [&] {
                    if (slabTau > 0.f) over(pix, slabTau, slabEmission / slabTau);
                    slabTau = 0.f, slabEmission = glm::vec3(0.f);
                };
                for (size_t k : order) {
                    const Primitive& p = prims[k];
                    if (p.kind == PrimitiveKind::Culled) continue;
                    if (p.slab != slabOf || p.kind != PrimitiveKind::Point) flush(), slabOf = p.slab;
                    if (T[pix] < kTransmittanceEpsilon) continue;
                    if (p.kind == PrimitiveKind::Point) {
                        const PointFootprint fp = rasterizePoint(PixelCoord(p.centre), p.variance);
                        if (x < fp.x0 || x >= fp.x0 + fp.nx || y < fp.y0 || y >= fp.y0 + fp.ny) continue;
                        const float tau = p.total * fp.at(x - fp.x0, y - fp.y0);
                        slabTau += tau, slabEmission += tau * p.color;
                    } else {
                        if (x < p.range.x0 || x > p.range.x1 || y < p.range.y0 || y > p.range.y1) continue;
                        const float dx = float(x) + 0.5f - p.centre.x, dy = float(y) + 0.5f - p.centre.y;
                        const float i2 = p.conic.x * dx * dx + 2.f * p.conic.y * dx * dy + p.conic.z * dy * dy;
                        if (!(i2 < 1.f)) continue;
                        SplatShader shader;
                        shader.row = tables().reindex.row(halfConeAngle(p.sin2Alpha));
                        shader.footprint = &tables().footprint;
                        shader.scale = p.scale;
                        const float tau = p.kind == PrimitiveKind::SplatExactIndex
                                              ? shader.depositAtD2(p.exactMap.d2(i2, dx, dy)) : shader.depositAtIndex2(i2);
                        over(pix, tau, p.color);
                    }
                }
                flush();
            }
    }
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = glm::vec4(C[i], 1.f - T[i]);
    return image;
}

/// Random voxels in two depth windows, projected with a hybrid context (points and splats),
/// dense enough that tiles go opaque (early termination is exercised too).
std::vector<std::vector<Primitive>> randomWindows(const Camera& camera, RenderMode mode) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    // h = 0.1: voxels at depth 20–36 project to 0.4–0.7 px (points), the near seventh to 1.3–2.2 px (splats).
    const ProjectionContext ctx{camera, tables(), 0.1, 0.1, mode, 1.0, FootprintPath::Auto, false};
    std::vector<std::vector<Primitive>> windows(2);
    for (int w = 0; w < 2; ++w)
        for (int i = 0; i < 3000; ++i) {
            const double depth = 20.0 + 8.0 * w + 8.0 * u(rng);
            const glm::dvec3 c((u(rng) - 0.5) * 0.5 * depth, (u(rng) - 0.5) * 0.5 * depth, depth * (w == 0 && i % 7 == 0 ? 0.3 : 1.0));
            Primitive p = projectVoxel(c, float(5.0 + 60.0 * u(rng)), glm::vec3(u(rng), u(rng), u(rng)), ctx);
            p.depth = float(glm::length(c));
            p.slab = int64_t(std::floor(p.depth / ctx.slabLength));
            windows[size_t(w)].push_back(p);
        }
    return windows;
}

Image fastComposite(const std::vector<std::vector<Primitive>>& windows, const Camera& camera, bool vector) {
    TileCompositor compositor(camera.width(), camera.height(), tables(), ExactContext{&camera, 0.1, vector});
    double bin = 0.0, comp = 0.0;
    for (const auto& prims : windows) compositor.composite(prims, bin, comp);
    return compositor.image();
}

double maxDifference(const Image& a, const Image& b) {
    double worst = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c) worst = std::max(worst, double(std::abs(a.pixels[i][c] - b.pixels[i][c])));
    return worst;
}

TEST(TileCompositor, MatchesTheSlowPerPixelCompositor) {
    const Camera camera = testCamera(72);  // 72 = 4.5 tiles: partial tiles at the edges
    for (const RenderMode mode : {RenderMode::Hybrid, RenderMode::Point, RenderMode::Splat, RenderMode::Ewa,
                                  RenderMode::Swan, RenderMode::None}) {
        const auto windows = randomWindows(camera, mode);
        int points = 0, splats = 0;
        for (const auto& w : windows)
            for (const Primitive& p : w) (p.kind == PrimitiveKind::Point ? points : splats) += p.kind != PrimitiveKind::Culled;
        const Image slow = slowComposite(windows, camera.width(), camera.height());
        const Image scalar = fastComposite(windows, camera, false), vector = fastComposite(windows, camera, true);
        double opaque = 0.0;
        for (const auto& px : slow.pixels) opaque += px.w > 0.999f;
        std::printf("  %s: %d points, %d splats, %.0f%% of pixels opaque; scalar %.2g, vector %.2g\n",
                    toString(mode).c_str(), points, splats, 100.0 * opaque / slow.pixels.size(),
                    maxDifference(scalar, slow), maxDifference(vector, slow));
        EXPECT_GT(opaque, 0.05 * slow.pixels.size()) << toString(mode);
        EXPECT_LT(maxDifference(scalar, slow), 1e-5) << toString(mode);  // same arithmetic, other order of sums
        // + the polynomial footprint: within 2e−5·F(0) of the tables (FootprintPoly.AgreesWithTheTablePath),
        // times σ up to 65 per voxel length here, through α and T.
        EXPECT_LT(maxDifference(vector, slow), 1e-4) << toString(mode);
    }
}

// The packed radix-sort key (compositor.cpp, KeyLayout) against the slow compositor's
// comparison sort where it is hardest: many equal keys (the index must break the tie, as
// the stable sort does), slabs spread over a million, depths from 0 (the eye) to 10⁶.
TEST(TileCompositor, OrderWithTiesAndWideKeyRanges) {
    const Camera camera = testCamera(72);
    auto windows = randomWindows(camera, RenderMode::Hybrid);
    std::mt19937 rng(17);
    std::uniform_int_distribution<int> pick(0, 5);
    for (auto& w : windows)
        for (size_t i = 0; i < w.size(); ++i) {
            Primitive& p = w[i];
            switch (pick(rng)) {
                case 0: p.depth = 25.f, p.slab = 250; break;  // ties: same slab, kind and depth
                case 1: p.depth = 0.f; break;
                case 2: p.depth = 1.0e6f, p.slab = 1000000; break;
                default: break;
            }
        }
    const Image slow = slowComposite(windows, camera.width(), camera.height());
    const Image scalar = fastComposite(windows, camera, false);
    std::printf("  scalar vs slow: %.2g\n", maxDifference(scalar, slow));
    EXPECT_LT(maxDifference(scalar, slow), 1e-5);
}

// Key and index share one 64-bit sort entry; where they would not fit, the key drops the depth's
// lowest bits. Forced here: slabs spread over 2^27 (28 bits of slab and kind), depths from 0 to
// 10⁶ (31 bits), 3 000 primitives (12 bits) make 71 bits, so 7 depth bits go. Every depth is
// distinct by far more than that (≥ 3·10⁻⁴ of it, the dropped bits 2⁻¹⁶), so the order, and the
// image, must still be the slow compositor's; a key that spilled into the index would scramble it.
TEST(TileCompositor, OrderWhenKeyAndIndexOverflowOneWord) {
    const Camera camera = testCamera(72);
    auto windows = randomWindows(camera, RenderMode::Hybrid);
    for (auto& w : windows)
        for (size_t i = 0; i < w.size(); ++i) {
            Primitive& p = w[i];
            p.depth = 20.f + 0.01f * float(i);  // distinct, 3·10⁻⁴ apart at most relative
            p.slab = int64_t(std::floor(p.depth / 0.1f));
            if (i == 7) p.depth = 0.f, p.slab = 0;
            if (i == 11) p.depth = 1.0e6f, p.slab = (int64_t(1) << 27) - 2;
        }
    const Image slow = slowComposite(windows, camera.width(), camera.height());
    const Image scalar = fastComposite(windows, camera, false);
    std::printf("  scalar vs slow: %.2g\n", maxDifference(scalar, slow));
    EXPECT_LT(maxDifference(scalar, slow), 1e-5);
}

// The compositor's image is the same, bit for bit, whatever the thread count.
TEST(TileCompositor, SameImageForAnyThreadCount) {
    const Camera camera = testCamera(72);
    const auto windows = randomWindows(camera, RenderMode::Hybrid);
    Image one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = fastComposite(windows, camera, true);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = fastComposite(windows, camera, true);
    }
    ASSERT_EQ(one.pixels, two.pixels);
}

// hidden() (the occlusion test for blocks and primitives) against brute force over the image:
// true exactly when every pixel of the rectangle, clamped to the image, has T < ε, including
// rectangles on the opaque side of a tile that still has live pixels (a tile-level test says no).
TEST(TileCompositor, HiddenIsExactPerPixel) {
    const Camera camera = testCamera(72);
    const auto windows = randomWindows(camera, RenderMode::Hybrid);
    TileCompositor compositor(camera.width(), camera.height(), tables(), ExactContext{&camera, 0.1, true});
    double bin = 0.0, comp = 0.0;
    for (const auto& prims : windows) compositor.composite(prims, bin, comp);
    const Image image = compositor.image();
    const int w = camera.width(), h = camera.height();
    const auto T = [&](int x, int y) { return 1.0 - double(image.pixels[size_t(y) * w + x].w); };
    std::mt19937 rng(23);
    std::uniform_int_distribution<int> corner(-6, 77), extent(0, 12);
    int hidden = 0, hiddenInLiveTiles = 0, checked = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const int x0 = corner(rng), y0 = corner(rng), x1 = x0 + extent(rng), y1 = y0 + extent(rng);
        bool all = true, ambiguous = false, liveTile = false;
        for (int y = std::max(y0, 0); y <= std::min(y1, h - 1); ++y)
            for (int x = std::max(x0, 0); x <= std::min(x1, w - 1); ++x) {
                all = all && T(x, y) < kTransmittanceEpsilon;
                ambiguous = ambiguous || std::abs(T(x, y) - kTransmittanceEpsilon) < 1e-6;  // alpha's rounding
            }
        if (ambiguous || x1 < 0 || y1 < 0 || x0 >= w || y0 >= h) continue;
        // Does a tile under the rectangle hold a live pixel anywhere (outside the rectangle too)?
        for (int ty = std::max(y0, 0) / kTileSize; ty <= std::min(y1, h - 1) / kTileSize; ++ty)
            for (int tx = std::max(x0, 0) / kTileSize; tx <= std::min(x1, w - 1) / kTileSize; ++tx)
                for (int y = ty * kTileSize; y < std::min(h, (ty + 1) * kTileSize); ++y)
                    for (int x = tx * kTileSize; x < std::min(w, (tx + 1) * kTileSize); ++x)
                        liveTile = liveTile || T(x, y) >= kTransmittanceEpsilon;
        ++checked;
        ASSERT_EQ(compositor.hidden(x0, y0, x1, y1), all) << x0 << "," << y0 << " .. " << x1 << "," << y1;
        hidden += all;
        hiddenInLiveTiles += all && liveTile;
    }
    std::printf("  %d rectangles: %d hidden, %d of them in tiles with live pixels\n", checked, hidden, hiddenInLiveTiles);
    EXPECT_GT(hiddenInLiveTiles, 100);  // the case a tile-level test misses is exercised
    EXPECT_LT(hidden, checked);
    // A rectangle wholly off the image covers no pixel, so it is hidden (it would draw nothing).
    EXPECT_TRUE(compositor.hidden(-9, 5, -1, 20));
    EXPECT_TRUE(compositor.hidden(5, h, 20, h + 9));
    EXPECT_TRUE(compositor.hidden(w, -3, w + 4, 2));
    EXPECT_TRUE(compositor.hidden(-40, -40, -33, -33));
}

// projectBatch is projectVoxel over the batch, in order, with the window's slab and depth, packed
// into the window's arrays (record, order key, depth, members, exact map, extra), and counted by
// kind; compacted by blocks of ProjectedWindow::kBlock voxels: a block's drawn primitives fill its
// slots from the front in voxel order, and its other slots are not drawn.
TEST(ProjectBatch, EqualsProjectVoxelOneByOne) {
    const Camera camera = testCamera(64);
    // h = 0.1: projected spacing 3 px at z = 4, 0.27 px at z = 44: points and splats.
    const ProjectionContext ctx{camera, tables(), 0.1, 0.1, RenderMode::Hybrid, 1.0, FootprintPath::Auto, false};
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    VoxelBatch batch;
    for (int i = 0; i < 5000; ++i) {
        const float z = 4.f + 40.f * u(rng);
        batch.viewPos.emplace_back((u(rng) - 0.5f) * z, (u(rng) - 0.5f) * z, z);
        batch.distance.push_back(glm::length(batch.viewPos.back()));
        batch.sigma.push_back(u(rng));
        batch.color.emplace_back(u(rng), u(rng), u(rng));
        batch.spread.push_back(i % 3 == 0 ? u(rng) : 0.f);
        batch.members.push_back(1 + uint32_t(i % 5));
    }
    batch.slabBegin = 3, batch.slabEnd = 200;
    ProjectedWindow window;
    window.resize(7000);  // larger than the batch: only the first 5000 are this window
    const ProjectionCounts counts = projectBatch(batch, ctx, window);
    ASSERT_EQ(window.size, batch.size());
    ASSERT_EQ(window.slabBase, 3);
    int kinds[6] = {};
    uint64_t drawnVoxels = 0;
    size_t slot = 0, drawnSlots = 0;
    for (size_t i = 0; i < batch.size(); ++i) {
        if (i % ProjectedWindow::kBlock == 0) slot = i;  // a block's slots start at its first voxel
        const Primitive q = projectVoxel(glm::dvec3(batch.viewPos[i]), batch.sigma[i], batch.color[i], ctx, batch.spread[i]);
        ++kinds[int(q.kind)];
        drawnVoxels += q.kind != PrimitiveKind::Culled ? batch.members[i] : 0;
        const bool drawn = q.kind != PrimitiveKind::Culled && !q.range.empty();
        if (!drawn) continue;  // no slot
        const size_t j = slot++;
        ++drawnSlots;
        const PrimitiveRecord& p = window.records[j];
        const bool point = q.kind == PrimitiveKind::Point;
        ASSERT_EQ(p.kind, q.kind) << i;
        ASSERT_EQ(p.centre, q.centre) << i;
        ASSERT_EQ(p.shape, point ? glm::vec3(q.pointInvVariance, q.total, q.pointNorm) : q.conic) << i;
        ASSERT_EQ(p.scale, point ? q.pointRadius2 : q.scale) << i;
        ASSERT_EQ(p.sin2Alpha, q.sin2Alpha) << i;
        ASSERT_EQ(p.color, q.color) << i;
        ASSERT_EQ(p.hasExactMap, q.hasExactMap) << i;
        ASSERT_TRUE(p.range.x0 == q.range.x0 && p.range.y0 == q.range.y0 && p.range.x1 == q.range.x1 &&
                    p.range.y1 == q.range.y1) << i;
        if (q.hasExactMap) {
            ASSERT_TRUE(window.exactMap(j) == q.exactMap) << i;
        }
        if (needsExtra(q.kind, q.hasExactMap)) {
            ASSERT_EQ(window.extra[j].viewPos, q.viewPos) << i;
        }
        ASSERT_EQ(window.members[j], batch.members[i]) << i;
        ASSERT_EQ(window.depth[j], batch.distance[i]) << i;
        const int64_t slab = std::clamp<int64_t>(int64_t(std::floor(batch.distance[i] / ctx.slabLength)), 3, 199);
        ASSERT_EQ(p.slab, uint32_t(slab - 3)) << i;
        ASSERT_EQ(window.order[j], uint32_t(slab - 3) * 2 + (point ? 0 : 1)) << i;
    }
    // Every slot past its block's drawn ones is not drawn.
    size_t notDrawn = 0;
    for (size_t j = 0; j < batch.size(); ++j) notDrawn += window.order[j] == ProjectedWindow::kNotDrawn;
    ASSERT_EQ(notDrawn, batch.size() - drawnSlots);
    EXPECT_GT(notDrawn, 0u);  // the case the compaction is for is exercised
    EXPECT_EQ(counts.points, uint64_t(kinds[int(PrimitiveKind::Point)]));
    EXPECT_EQ(counts.drawnVoxels, drawnVoxels);
    EXPECT_GT(kinds[int(PrimitiveKind::Point)], 100);
    EXPECT_GT(kinds[int(PrimitiveKind::Splat)] + kinds[int(PrimitiveKind::SplatExactIndex)], 100);
}

}  // namespace
}  // namespace vdbsplat
