// composite/point_raster.cpp — a point's filter over one tile with Google Highway (see
// point_raster.h). Compiled once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks
// the best the CPU supports at run time. Built with -ffp-contract=off (CMakeLists.txt): a fused
// multiply-add would round differently from the scalar oracle.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite/point_raster.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>

#include "composite/point_raster.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kStride = 16;  // tile row stride (kTileSize)

/// PointFilterTable::weight on every lane: 0 where !(x < maxX); else the linear lookup, with
/// weight()'s float operations (two gathers: cheaper here than a scalar lookup per pixel row
/// and column).
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Weight(D d, const PointFilterTable& table, V x) {
    const hn::RebindToSigned<D> di;
    const auto valid = hn::Lt(x, hn::Set(d, PointFilterTable::maxX()));  // false for NaN
    const V t = hn::Mul(hn::Max(hn::IfThenElseZero(valid, x), hn::Zero(d)), hn::Set(d, table.indexScale()));
    const auto k = hn::Min(hn::ConvertTo(di, t), hn::Set(di, PointFilterTable::kIntervals - 1));
    const V w = hn::Sub(t, hn::ConvertTo(d, k));
    const V v0 = hn::GatherIndex(d, table.values(), k), v1 = hn::GatherIndex(d, table.values() + 1, k);
    return hn::IfThenElseZero(valid, hn::Add(v0, hn::Mul(w, hn::Sub(v1, v0))));
}

/// The squared offsets (x + ½ − c)² of the tile's 16 columns (or rows) from @p c, and their
/// weights, into @p sq and @p g (for the vectors from @p first to @p last).
template <class D>
HWY_INLINE void AxisWeights(D d, const PointFilterTable& table, int origin, float c, float invV, int first, int last,
                            float* sq, float* g) {
    constexpr int N = int(hn::MaxLanes(D()));
    const hn::RebindToSigned<D> di;
    for (int k = first; k <= last; k += N) {
        const auto x = hn::ConvertTo(d, hn::Iota(di, origin + k));
        const auto dx = hn::Sub(hn::Add(x, hn::Set(d, 0.5f)), hn::Set(d, c));
        const auto dx2 = hn::Mul(dx, dx);
        hn::Store(dx2, d, sq + k);
        hn::Store(Weight(d, table, hn::Mul(dx2, hn::Set(d, invV))), d, g + k);
    }
}

template <class D>
void DrawPointFor(D d, const PointRaster& p, const SlabTile& tile) {
    using V = hn::Vec<D>;
    constexpr int N = int(hn::MaxLanes(D()));
    const hn::RebindToSigned<D> di;
    const PointFilterTable& table = *p.table;
    // The tile's columns in vectors of N: the first and last that hold footprint pixels.
    const int c0 = (p.x0 - tile.x0) / N * N, c1 = (p.x1 - tile.x0) / N * N;
    const int r0 = (p.y0 - tile.y0) / N * N, r1 = (p.y1 - tile.y0) / N * N;
    // Per column and per row of the tile (once per point and tile): the squared offset and its weight.
    alignas(64) float dx2s[kStride], gxs[kStride], dy2s[kStride], gys[kStride];
    AxisWeights(d, table, tile.x0, p.cx, p.invVariance, c0, c1, dx2s, gxs);
    AxisWeights(d, table, tile.y0, p.cy, p.invVariance, r0, r1, dy2s, gys);
    const V eps = hn::Set(d, p.epsilon), rs2 = hn::Set(d, p.radius2), total = hn::Set(d, p.total),
            norm = hn::Set(d, p.norm);
    const V cr = hn::Set(d, p.color.x), cg = hn::Set(d, p.color.y), cb = hn::Set(d, p.color.z);
    const auto before = hn::Set(di, p.x0 - tile.x0 - 1), after = hn::Set(di, p.x1 - tile.x0 + 1);
    for (int y = p.y0; y <= p.y1; ++y) {
        const int ly = y - tile.y0, row = ly * kStride;
        const V gy = hn::Set(d, gys[ly]), vdy2 = hn::Set(d, dy2s[ly]);
        for (int c = c0; c <= c1; c += N) {
            const auto col = hn::Iota(di, c);
            const auto inRange = hn::RebindMask(d, hn::And(hn::Gt(col, before), hn::Lt(col, after)));
            const V dx2 = hn::Load(d, dx2s + c);
            const auto mask = hn::And(hn::And(inRange, hn::Ge(hn::Load(d, tile.T + row + c), eps)),
                                      hn::Lt(hn::Add(dx2, vdy2), rs2));
            if (hn::AllFalse(d, mask)) continue;
            const V tau = hn::Mul(total, hn::Mul(hn::Mul(hn::Load(d, gxs + c), gy), norm));
            float* const pt = tile.tau + row + c;
            float* const pr = tile.er + row + c;
            float* const pg = tile.eg + row + c;
            float* const pb = tile.eb + row + c;
            const V t0 = hn::Load(d, pt), r0v = hn::Load(d, pr), g0 = hn::Load(d, pg), b0 = hn::Load(d, pb);
            hn::Store(hn::IfThenElse(mask, hn::Add(t0, tau), t0), d, pt);
            hn::Store(hn::IfThenElse(mask, hn::Add(r0v, hn::Mul(tau, cr)), r0v), d, pr);
            hn::Store(hn::IfThenElse(mask, hn::Add(g0, hn::Mul(tau, cg)), g0), d, pg);
            hn::Store(hn::IfThenElse(mask, hn::Add(b0, hn::Mul(tau, cb)), b0), d, pb);
        }
    }
}

void DrawPoint(const PointRaster& p, const SlabTile& tile) {
    if (p.x0 > p.x1 || p.y0 > p.y1) return;
    DrawPointFor(hn::CappedTag<float, kStride>(), p, tile);
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(DrawPoint);

void drawPointVector(const PointRaster& p, const SlabTile& tile) { HWY_DYNAMIC_DISPATCH(DrawPoint)(p, tile); }

void drawPointScalar(const PointRaster& p, const SlabTile& tile) {
    constexpr int kStride = 16;
    const PointFilterTable& table = *p.table;
    for (int y = p.y0; y <= p.y1; ++y) {
        const float dy = PointSetup::offset(y, p.cy), dy2 = dy * dy;
        const float gy = table.weight(dy2 * p.invVariance);
        for (int x = p.x0; x <= p.x1; ++x) {
            const int i = (y - tile.y0) * kStride + (x - tile.x0);
            if (!(tile.T[i] >= p.epsilon)) continue;
            const float dx = PointSetup::offset(x, p.cx), dx2 = dx * dx;
            const float w = dx2 + dy2 < p.radius2 ? table.weight(dx2 * p.invVariance) * gy : 0.0f;
            const float tau = p.total * (w * p.norm);
            tile.tau[i] += tau;
            tile.er[i] += tau * p.color.x;
            tile.eg[i] += tau * p.color.y;
            tile.eb[i] += tau * p.color.z;
        }
    }
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
