// composite/point_raster.cpp — a point's filter over one tile with Google Highway (see
// point_raster.h). Compiled once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks
// the best the CPU supports at run time. Built with -ffp-contract=off (CMakeLists.txt): a fused
// multiply-add would round differently from the scalar oracle.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite/point_raster.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "pointfilter/point_weight-inl.h"

#include <algorithm>

#include "composite/point_raster.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kStride = kTileSize;  // tile row stride


/// kSlabs false: the kernel order, into one slab's sums (@p tile); true: into @p slabs by their
/// fractions. A template argument, so the kernel order's loop is the code it was before the slab
/// order (through a one-slab SlabTargets it cost the far views' point loop 20 %). kGrey: @p tile or
/// @p slabs have no green and blue sums (ColorChannels::Grey), only τ and the red ones are written.
template <bool kSlabs, bool kGrey, class D>
void DrawPointFor(D d, const PointRaster& p, const SlabTargets* slabs, const SlabTile* tile, const float* T, int tileX0,
                  int tileY0) {
    using V = hn::Vec<D>;
    constexpr int N = int(hn::MaxLanes(D()));
    const hn::RebindToSigned<D> di;
    // The tile's columns in vectors of N: the first and last that hold footprint pixels.
    const int c0 = (p.x0 - tileX0) / N * N, c1 = (p.x1 - tileX0) / N * N;
    // Per column and per row of the footprint's part in the tile (once per point and tile): the
    // squared offset and its weight, both axes in one vector of 16 (lanes 0–7 the columns from
    // p.x0, 8–15 the rows from p.y0: one PointWeight), then put on the tile's lanes.
    alignas(64) float sq[16], g[16];
    AxisWeights(p.x0, p.y0, p.cx, p.cy, p.invVariance, sq, g);
    // The columns on the tile's lanes: lanes past the footprint's part hold other columns' values
    // (or zeros), masked off below.
    alignas(64) float dx2s[kStride + 8] = {}, gxs[kStride + 8] = {};
    const int at = p.x0 - tileX0;
    std::copy_n(sq, 8, dx2s + at), std::copy_n(g, 8, gxs + at);
    const V eps = hn::Set(d, p.epsilon), rs2 = hn::Set(d, p.radius2), total = hn::Set(d, p.total),
            norm = hn::Set(d, p.norm);
    const V cr = hn::Set(d, p.color.x), cg = hn::Set(d, p.color.y), cb = hn::Set(d, p.color.z);
    const auto before = hn::Set(di, p.x0 - tileX0 - 1), after = hn::Set(di, p.x1 - tileX0 + 1);
    for (int y = p.y0; y <= p.y1; ++y) {
        const int ly = y - p.y0, row = (y - tileY0) * kStride;
        const V gy = hn::Set(d, g[8 + ly]), vdy2 = hn::Set(d, sq[8 + ly]);
        for (int c = c0; c <= c1; c += N) {
            const auto col = hn::Iota(di, c);
            const auto inRange = hn::RebindMask(d, hn::And(hn::Gt(col, before), hn::Lt(col, after)));
            const V dx2 = hn::Load(d, dx2s + c);
            const auto mask = hn::And(hn::And(inRange, hn::Ge(hn::Load(d, T + row + c), eps)),
                                      hn::Lt(hn::Add(dx2, vdy2), rs2));
            if (hn::AllFalse(d, mask)) continue;
            const V tauAll = hn::Mul(total, hn::Mul(hn::Mul(hn::Load(d, gxs + c), gy), norm));
            const auto deposit = [&](V tau, float* sumTau, float* sumR, float* sumG, float* sumB) {
                float* const pt = sumTau + row + c;
                float* const pr = sumR + row + c;
                const V t0 = hn::Load(d, pt), r0v = hn::Load(d, pr);
                hn::Store(hn::IfThenElse(mask, hn::Add(t0, tau), t0), d, pt);
                hn::Store(hn::IfThenElse(mask, hn::Add(r0v, hn::Mul(tau, cr)), r0v), d, pr);
                if constexpr (kGrey) return;
                float* const pg = sumG + row + c;
                float* const pb = sumB + row + c;
                const V g0 = hn::Load(d, pg), b0 = hn::Load(d, pb);
                hn::Store(hn::IfThenElse(mask, hn::Add(g0, hn::Mul(tau, cg)), g0), d, pg);
                hn::Store(hn::IfThenElse(mask, hn::Add(b0, hn::Mul(tau, cb)), b0), d, pb);
            };
            if constexpr (kSlabs) {
                for (int j = 0; j < slabs->count; ++j)
                    deposit(hn::Mul(tauAll, hn::Set(d, slabs->fraction[size_t(j)])), slabs->tau[size_t(j)],
                            slabs->er[size_t(j)], slabs->eg[size_t(j)], slabs->eb[size_t(j)]);
            } else {
                deposit(tauAll, tile->tau, tile->er, tile->eg, tile->eb);
            }
        }
    }
}

#if HWY_TARGET != HWY_SCALAR
constexpr int kPairLanes = 16;  // DrawPointPairs: two rows of 8 pixels per vector (16-lane targets)

/// DrawPointFor on a 16-lane target, two rows a vector: a point's part in a tile is at most
/// kPointMaxSide ≤ 8 columns wide, so a window of 8 columns from its first (moved left to stay in
/// the row) holds it, and rows y and y + 1 share one vector (lower half row y, upper half y + 1),
/// where one vector per row left half its lanes or more idle. The window's columns and the rows get
/// their squared offsets and weights from AxisWeights, as DrawPointFor's; every pixel then takes
/// DrawPointFor's operations, so the same sums bit for bit.
template <bool kSlabs, bool kGrey, class D>
void DrawPointPairs(D d, const PointRaster& p, const SlabTargets* slabs, const SlabTile* tile, const float* T, int tileX0,
                    int tileY0) {
    using V = hn::Vec<D>;
    const hn::Half<D> dh;
    const hn::RebindToSigned<D> di;
    constexpr int kHalf = kPairLanes / 2;
    const int start = std::min(p.x0 - tileX0, kStride - kHalf);  // the window's first column in the tile
    alignas(64) float sq[kPairLanes], g[kPairLanes];  // lanes 0–7 the window's columns, 8–15 the rows
    AxisWeights(tileX0 + start, p.y0, p.cx, p.cy, p.invVariance, sq, g);
    const V dx2 = hn::Combine(d, hn::Load(dh, sq), hn::Load(dh, sq)), gx = hn::Combine(d, hn::Load(dh, g), hn::Load(dh, g));
    const V eps = hn::Set(d, p.epsilon), rs2 = hn::Set(d, p.radius2), total = hn::Set(d, p.total), norm = hn::Set(d, p.norm);
    const V cr = hn::Set(d, p.color.x), cg = hn::Set(d, p.color.y), cb = hn::Set(d, p.color.z);
    // The footprint's columns, in each half.
    const auto column = hn::Add(hn::Set(di, tileX0 + start), hn::Combine(di, hn::Iota(hn::Half<decltype(di)>(), 0), hn::Iota(hn::Half<decltype(di)>(), 0)));
    const auto columns = hn::RebindMask(d, hn::And(hn::Gt(column, hn::Set(di, p.x0 - 1)), hn::Lt(column, hn::Set(di, p.x1 + 1))));
    const auto lowerHalf = hn::FirstN(d, size_t(kHalf));
    for (int y = p.y0; y <= p.y1; y += 2) {
        const bool pair = y < p.y1;  // else a lone last row: its upper half repeats it, masked off
        const int ka = y - p.y0, kb = pair ? ka + 1 : ka;
        const int offA = (y - tileY0) * kStride + start, offB = pair ? offA + kStride : offA;
        const auto both = [&](const float* a) { return hn::Combine(d, hn::Set(dh, a[kHalf + kb]), hn::Set(dh, a[kHalf + ka])); };
        const V dy2 = both(sq), gy = both(g);
        const auto load = [&](const float* base) { return hn::Combine(d, hn::LoadU(dh, base + offB), hn::LoadU(dh, base + offA)); };
        const auto mask = hn::And(hn::And(pair ? columns : hn::And(columns, lowerHalf), hn::Ge(load(T), eps)),
                                  hn::Lt(hn::Add(dx2, dy2), rs2));
        if (hn::AllFalse(d, mask)) continue;
        const V tauAll = hn::Mul(total, hn::Mul(hn::Mul(gx, gy), norm));
        const auto deposit = [&](V tau, float* sumTau, float* sumR, float* sumG, float* sumB) {
            const auto store = [&](float* base, V value) {
                hn::StoreU(hn::LowerHalf(dh, value), dh, base + offA);
                if (pair) hn::StoreU(hn::UpperHalf(dh, value), dh, base + offB);
            };
            const V t0 = load(sumTau), r0 = load(sumR);
            store(sumTau, hn::IfThenElse(mask, hn::Add(t0, tau), t0));
            store(sumR, hn::IfThenElse(mask, hn::Add(r0, hn::Mul(tau, cr)), r0));
            if constexpr (kGrey) return;
            const V g0 = load(sumG), b0 = load(sumB);
            store(sumG, hn::IfThenElse(mask, hn::Add(g0, hn::Mul(tau, cg)), g0));
            store(sumB, hn::IfThenElse(mask, hn::Add(b0, hn::Mul(tau, cb)), b0));
        };
        if constexpr (kSlabs) {
            for (int j = 0; j < slabs->count; ++j)
                deposit(hn::Mul(tauAll, hn::Set(d, slabs->fraction[size_t(j)])), slabs->tau[size_t(j)], slabs->er[size_t(j)],
                        slabs->eg[size_t(j)], slabs->eb[size_t(j)]);
        } else {
            deposit(tauAll, tile->tau, tile->er, tile->eg, tile->eb);
        }
    }
}
#endif  // HWY_TARGET != HWY_SCALAR

/// The point's pixels in the tile: two rows a vector where vectors hold 16 floats, else one row.
template <bool kSlabs, bool kGrey = false>
void DrawPointIn(const PointRaster& p, const SlabTargets* slabs, const SlabTile* tile, const float* T, int x0, int y0) {
#if HWY_TARGET != HWY_SCALAR
    using D16 = hn::CappedTag<float, kPairLanes>;
    if constexpr (hn::MaxLanes(D16()) == kPairLanes) {
        static_assert(kPointMaxSide <= kPairLanes / 2, "a point's columns fit half a vector");
        if (hn::Lanes(D16()) == kPairLanes) return DrawPointPairs<kSlabs, kGrey>(D16(), p, slabs, tile, T, x0, y0);
    }
#endif
    DrawPointFor<kSlabs, kGrey>(hn::CappedTag<float, kStride>(), p, slabs, tile, T, x0, y0);
}

void DrawPoint(const PointRaster& p, const SlabTile& tile) {
    if (p.x0 > p.x1 || p.y0 > p.y1) return;
    if (!tile.eg) return DrawPointIn<false, true>(p, nullptr, &tile, tile.T, tile.x0, tile.y0);
    DrawPointIn<false>(p, nullptr, &tile, tile.T, tile.x0, tile.y0);
}

void DrawPointSlabs(const PointRaster& p, const SlabTargets& slabs, const float* T, int x0, int y0) {
    if (p.x0 > p.x1 || p.y0 > p.y1) return;
    if (!slabs.eg[0]) return DrawPointIn<true, true>(p, &slabs, nullptr, T, x0, y0);
    DrawPointIn<true>(p, &slabs, nullptr, T, x0, y0);
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(DrawPoint);
HWY_EXPORT(DrawPointSlabs);

namespace {
SlabTargets oneSlab(const SlabTile& tile) {
    SlabTargets t;
    t.count = 1;
    t.tau[0] = tile.tau, t.er[0] = tile.er, t.eg[0] = tile.eg, t.eb[0] = tile.eb;
    t.fraction[0] = 1.f;
    return t;
}
}  // namespace

void drawPointSlabsVector(const PointRaster& p, const SlabTargets& slabs, const float* T, int x0, int y0) {
    HWY_DYNAMIC_DISPATCH(DrawPointSlabs)(p, slabs, T, x0, y0);
}

void drawPointVector(const PointRaster& p, const SlabTile& tile) { HWY_DYNAMIC_DISPATCH(DrawPoint)(p, tile); }

void drawPointSlabsScalar(const PointRaster& p, const SlabTargets& slabs, const float* T, int x0, int y0) {
    constexpr int kStride = kTileSize;
    for (int y = p.y0; y <= p.y1; ++y) {
        const float dy = PointSetup::offset(y, p.cy), dy2 = dy * dy;
        const float gy = pointFilterWeight(dy2 * p.invVariance);
        for (int x = p.x0; x <= p.x1; ++x) {
            const int i = (y - y0) * kStride + (x - x0);
            if (!(T[i] >= p.epsilon)) continue;
            const float dx = PointSetup::offset(x, p.cx), dx2 = dx * dx;
            const float w = dx2 + dy2 < p.radius2 ? pointFilterWeight(dx2 * p.invVariance) * gy : 0.0f;
            const float tauAll = p.total * (w * p.norm);
            for (int j = 0; j < slabs.count; ++j) {
                const float tau = tauAll * slabs.fraction[size_t(j)];
                slabs.tau[size_t(j)][i] += tau;
                slabs.er[size_t(j)][i] += tau * p.color.x;
                if (!slabs.eg[size_t(j)]) continue;  // one channel
                slabs.eg[size_t(j)][i] += tau * p.color.y;
                slabs.eb[size_t(j)][i] += tau * p.color.z;
            }
        }
    }
}

void drawPointScalar(const PointRaster& p, const SlabTile& tile) { drawPointSlabsScalar(p, oneSlab(tile), tile.T, tile.x0, tile.y0); }

}  // namespace vdbsplat
#endif  // HWY_ONCE
