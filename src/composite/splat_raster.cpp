// composite/splat_raster.cpp — the splat loop over one tile with Google Highway (see splat_raster.h).
// Compiled once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the
// CPU supports at run time.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite/splat_raster.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <type_traits>

#include "composite/opacity.h"
#include "composite/splat_raster.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kStride = kTileSize;  // tile row stride
constexpr int kPairLanes = 16;  // DrawRowPairs: two rows of 8 pixels per vector (16-lane targets)

/// Where a splat's deposits go, a template argument of every loop (so each is the code it would be
/// alone: a branch per vector, with the other deposits inlined beside it, cost the kernel order 15 %
/// when the slab order came): "over" the tile's four channels, or the slab sums (--compositing
/// slabs); each also with one channel (TileBuffers without G and B, SlabTargets without green and
/// blue sums: every colour grey, ColorChannels::Grey), T and R or τ and the red sums alone.
enum class Sink { Over, OverGrey, Slabs, SlabsGrey };
constexpr bool IsSlabs(Sink k) { return k == Sink::Slabs || k == Sink::SlabsGrey; }
constexpr bool IsGrey(Sink k) { return k == Sink::OverGrey || k == Sink::SlabsGrey; }

/// The exact d² = 1 − (1 − i²)/w from the affine index i² and the map's w at the same pixel
/// (ExactIndexMap::d2), clamped at 0.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V ExactFromIndex(D d, V i2, V w) {
    const V one = hn::Set(d, 1.f);
    return hn::Max(hn::Sub(one, hn::Div(hn::Sub(one, i2), w)), hn::Zero(d));
}

/// The map's w = w0 + dx·(wx + wxx·dx) + dy·(wy + wxy·dx + wyy·dy) at pixel offsets (dx, dy) from
/// the centre, in two parts that depend on dx alone (a loop whose dx is fixed sets them up once):
/// WAlongX = w0 + dx·(wx + wxx·dx), WCross = wy + wxy·dx, and w = WAlongX + dy·(wyy·dy + WCross).
template <class D, class V = hn::Vec<D>>
HWY_INLINE V WAlongX(D d, const ExactIndexMap& m, V dx) {
    return hn::MulAdd(dx, hn::MulAdd(hn::Set(d, m.wxx), dx, hn::Set(d, m.wx)), hn::Set(d, m.w0));
}
template <class D, class V = hn::Vec<D>>
HWY_INLINE V WCross(D d, const ExactIndexMap& m, V dx) {
    return hn::MulAdd(hn::Set(d, m.wxy), dx, hn::Set(d, m.wy));
}
template <class D, class V = hn::Vec<D>>
HWY_INLINE V MapW(D d, const ExactIndexMap& m, V dx, V dy) {
    return hn::MulAdd(hn::MulAdd(hn::Set(d, m.wyy), dy, WCross(d, m, dx)), dy, WAlongX(d, m, dx));
}

/// τ of the splat at index t (i², or the exact d²): τ = scale·√(1 − t)·G(2t − 1) (Horner,
/// footprint_poly.h). i² ≥ 0 but for rounding (a few ulps below 0 at the centre, where the
/// polynomial is as good; the exact d² is clamped at 0), so only t ≤ 1 is enforced: the lanes
/// outside the ellipse then stay finite, and the opacity's test per vector sees no NaN.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V TauAt(D d, const SplatRaster& s, V t) {
    const V zero = hn::Zero(d), one = hn::Set(d, 1.f), two = hn::Set(d, 2.f);
    t = hn::Min(t, one);
    const V x = hn::MulSub(two, t, one);
    V p = hn::Set(d, s.coef[FootprintPolynomials::kDegree]);
#pragma GCC unroll 16
    for (int j = FootprintPolynomials::kDegree - 1; j >= 0; --j) p = hn::MulAdd(p, x, hn::Set(d, s.coef[size_t(j)]));
    return hn::Max(hn::Mul(hn::Mul(hn::Set(d, s.scale), hn::Sqrt(hn::Sub(one, t))), p), zero);
}

/// τ of the splat at index @p i2 (the lanes inside its ellipse, i² < 1): at t = i², or, for the
/// exact index, at d² from i² and the map's w at the same pixels (@p w(), called only then). In
/// the ellipse d² < 1 up to rounding, where TauAt's t ≤ 1 gives τ = 0: no narrower mask.
template <class D, class WFn, class V = hn::Vec<D>>
HWY_INLINE V Tau(D d, const SplatRaster& s, V i2, const WFn& w) {
    return TauAt(d, s, s.exactIndex ? ExactFromIndex(d, i2, w()) : i2);
}

/// 1 − e^{−τ} ≈ τ·Σ_{k<K} (−τ)^k/(k + 1)!, the Taylor series to τ^K (Horner: K − 1 FMAs and a product).
template <int K, class D, class V = hn::Vec<D>>
HWY_INLINE V OpacitySeriesTo(D d, V tau) {
    static_assert(K >= 1 && K <= 8);
    constexpr float c[8] = {1.f, -0.5f, 1.f / 6.f, -1.f / 24.f, 1.f / 120.f, -1.f / 720.f, 1.f / 5040.f, -1.f / 40320.f};
    V p = hn::Set(d, c[K - 1]);
    for (int k = K - 2; k >= 0; --k) p = hn::MulAdd(p, tau, hn::Set(d, c[k]));
    return hn::Mul(p, tau);
}

/// α = 1 − e^{−τ} for τ ≥ 0, the splat's series (OpacitySeries) or, for Any: A vector whose lanes all have τ < 1/2 takes the Taylor series to τ⁸
/// (Horner, 7 FMAs and a product): its truncation error is below τ⁹/9!, i.e. below 1.4e−8·α for
/// every τ < 1/2 (α > 0.39·2τ there), under float rounding, and it has no cancellation for
/// small τ. Any other vector takes Highway's Expm1 (≈ 30 operations: a fifth of the framed
/// Engine's compositing when it served every vector). Semi-transparent volumes are almost all
/// series; an opaque voxel's deposits take Expm1.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V OpacityFromTau(D d, V tau, OpacitySeries series = OpacitySeries::Any) {
    // A splat whose every τ is small (opacitySeriesFor): a shorter series, no test per vector.
    if (series == OpacitySeries::Degree4) return OpacitySeriesTo<4>(d, tau);
    if (series == OpacitySeries::Degree6) return OpacitySeriesTo<6>(d, tau);
    if (hn::AllTrue(d, hn::Lt(tau, hn::Set(d, 0.5f)))) return OpacitySeriesTo<8>(d, tau);
    return hn::Neg(hn::Expm1(d, hn::Neg(tau)));  // 1 − e^{−τ}
}

/// --compositing slabs: τ·fraction_j and τ·fraction_j·c added to slab j's sums at the lanes of
/// @p mask; @p load and @p store read and write one vector of a tile array at the lanes' pixels.
template <bool kGrey, class D, class V, class M, class Load, class Store>
HWY_INLINE void DepositSlabs(D d, const SplatRaster& s, V tau, M mask, const Load& load, const Store& store) {
    const V cr = hn::Set(d, s.color.x), cg = hn::Set(d, s.color.y), cb = hn::Set(d, s.color.z);
    const SlabTargets& slabs = *s.slabs;
    // Lanes outside the mask add 0 (exactly: x + 0 = x, and 0·c + x = x for finite c).
    const V tauIn = hn::IfThenElseZero(mask, tau);
    for (int j = 0; j < slabs.count; ++j) {
        const V tj = hn::Mul(tauIn, hn::Set(d, slabs.fraction[size_t(j)]));
        float *pt = slabs.tau[size_t(j)], *pr = slabs.er[size_t(j)];
        store(pt, hn::Add(load(pt), tj));
        store(pr, hn::MulAdd(tj, cr, load(pr)));
        if constexpr (kGrey) continue;
        float *pg = slabs.eg[size_t(j)], *pb = slabs.eb[size_t(j)];
        store(pg, hn::MulAdd(tj, cg, load(pg)));
        store(pb, hn::MulAdd(tj, cb, load(pb)));
    }
}

/// The remainder (takeTransmittance, composite/opacity.h): where the transmittance @p next = T − T·α
/// a deposit leaves falls below ε, the deposit's share @p ta becomes all of @p T and @p next 0.
template <class D, class V>
HWY_INLINE void TakeRemainder(D d, V T, float epsilon, V& ta, V& next) {
    const auto goesOn = hn::Ge(next, hn::Set(d, epsilon));
    ta = hn::IfThenElse(goesOn, ta, T);
    next = hn::IfThenElseZero(goesOn, next);
}

/// "Over" at the lanes of @p mask (DESIGN §4): α = 1 − e^{−τ}, C += T·α·c, T' = T − T·α, except
/// where T' < ε, which takes the whole remainder: C += T·c, T' = 0 (the deposit that finishes a
/// pixel stands for what lies behind it; docs/compositing.md, "Early termination and the
/// remainder"). @p load and @p store as Deposit's. No lane at or above @p safeT
/// (SplatRaster::safeT) can finish, so a vector none of whose drawn lanes lies below it skips the
/// test, which waits on α and cost 10 % of the loop when every vector took it (docs/performance.md,
/// session 40).
template <bool kGrey, class D, class V, class M, class Load, class Store>
HWY_INLINE void Over(D d, V alpha, V T, float epsilon, float safeT, M mask, const V (&rgb)[3], const TileBuffers& tile,
                     const Load& load, const Store& store) {
    V ta = hn::Mul(T, alpha);   // T·α
    V next = hn::Sub(T, ta);    // T·(1 − α)
    if (HWY_UNLIKELY(!hn::AllFalse(d, hn::And(mask, hn::Lt(T, hn::Set(d, safeT)))))) TakeRemainder(d, T, epsilon, ta, next);
    const V R = load(tile.R);
    store(tile.R, hn::IfThenElse(mask, hn::MulAdd(ta, rgb[0], R), R));
    if constexpr (!kGrey) {
        const V G = load(tile.G), B = load(tile.B);
        store(tile.G, hn::IfThenElse(mask, hn::MulAdd(ta, rgb[1], G), G));
        store(tile.B, hn::IfThenElse(mask, hn::MulAdd(ta, rgb[2], B), B));
    }
    store(tile.T, hn::IfThenElse(mask, next, T));
}

/// The splat's τ at the lanes of @p mask deposited into the tile, every loop's last step: into the
/// slab sums (DepositSlabs), or "over" (Over, with its remainder), with @p T
/// the lanes' transmittance already loaded and @p rgb the splat's colour broadcast (by the caller,
/// before its loop: read from the SplatRaster after the tile's stores it would be loaded again per
/// vector, as the stores may alias it). @p load and @p store read and write one vector of a tile
/// array at the lanes' pixels (one row's, or two rows' halves).
template <Sink kSink, class D, class V, class M, class Load, class Store>
HWY_INLINE void Deposit(D d, const SplatRaster& s, const TileBuffers& tile, V tau, V T, M mask, const V (&rgb)[3],
                        const Load& load, const Store& store) {
    if constexpr (IsSlabs(kSink)) {
        DepositSlabs<IsGrey(kSink)>(d, s, tau, mask, load, store);
    } else {
        Over<IsGrey(kSink)>(d, OpacityFromTau(d, tau, s.series), T, s.epsilon, s.safeT, mask, rgb, tile, load, store);
    }
}

/// i² = Qxx dx² + 2 Qxy dx dy + Qyy dy²
template <class D, class V = hn::Vec<D>>
HWY_INLINE V IndexSquared(D d, const SplatRaster& s, V dx, V dy) {
    return hn::MulAdd(hn::Mul(hn::Set(d, s.qxx), dx), dx,
                      hn::Mul(hn::MulAdd(hn::Set(d, 2.f * s.qxy), dx, hn::Mul(hn::Set(d, s.qyy), dy)), dy));
}

/// What DrawRowsWide needs of each of a splat's rows in a tile (index k: row y0 + k), set up a
/// vector of rows at a time: the row's chord [xa, xb] in tile columns (xa > xb: none) and, with
/// dx the pixel centre's x − cx, the row's quadratics in dx:
///     i² = i0 + dx·(i1 + Qxx·dx)     (i0 = Qyy dy², i1 = 2 Qxy dy)
///     w  = w0 + dx·(w1 + wxx·dx)     (exact index: w0 = map.w0 + dy·(map.wy + wyy·dy),
///                                     w1 = map.wx + wxy·dy; ExactIndexMap)
/// so that a vector of pixels costs two FMAs per quadratic.
struct RowQuadratics {
    static constexpr int kMax = kTileSize + 16;  ///< rows of a tile, and a last vector's spill
    alignas(64) int32_t xa[kMax], xb[kMax];
    alignas(64) float i0[kMax], i1[kMax];
    alignas(64) float w0[kMax], w1[kMax];
};

/// Every row's chord of the support ellipse i² < 1, one reciprocal for its two roots (as
/// DrawRowPairsIfNarrow: the chord keeps a pixel of slack each side and the mask i² < 1 decides
/// every pixel), and its quadratics. The chord is clamped as integers to [x0, x1 + 1] and
/// [x0 − 1, x1], so that no conic (a NaN or an infinity converted to an integer included) can
/// send the row loop outside the tile.
template <class D>
HWY_INLINE void SetUpRows(D d, const SplatRaster& s, const TileBuffers& tile, RowQuadratics& q) {
    using V = hn::Vec<D>;
    const hn::RebindToSigned<D> di;
    const int n = int(hn::Lanes(d)), rows = s.y1 - s.y0 + 1;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.f);
    const V base = hn::Set(d, s.cx - 0.5f), invQxx = hn::Set(d, 1.f / s.qxx);
    const auto x0 = hn::Set(di, s.x0), x1 = hn::Set(di, s.x1), oneI = hn::Set(di, 1);
    const auto tileX0 = hn::Set(di, tile.x0);
    for (int k = 0; k < rows; k += n) {
        const V dy = hn::Sub(hn::Iota(d, float(s.y0 + k) + 0.5f), hn::Set(d, s.cy));  // float(y) + 0.5 − cy
        const V b = hn::Mul(hn::Set(d, s.qxy), dy);
        const V disc = hn::Sub(hn::Mul(b, b), hn::Mul(hn::Set(d, s.qxx), hn::Sub(hn::Mul(hn::Mul(hn::Set(d, s.qyy), dy), dy), one)));
        const auto has = hn::Gt(disc, zero);
        const V root = hn::Sqrt(hn::Max(disc, zero));
        const V lo = hn::MulAdd(hn::Sub(hn::Neg(b), root), invQxx, base);
        const V hi = hn::MulAdd(hn::Sub(root, b), invQxx, base);
        const auto xa = hn::Sub(hn::Min(hn::Max(hn::ConvertTo(di, hn::Floor(lo)), x0), hn::Add(x1, oneI)), tileX0);
        const auto xb = hn::Sub(hn::Max(hn::Min(hn::ConvertTo(di, hn::Ceil(hi)), x1), hn::Sub(x0, oneI)), tileX0);
        hn::StoreU(xa, di, q.xa + k);
        hn::StoreU(hn::IfThenElse(hn::RebindMask(di, has), xb, hn::Sub(xa, oneI)), di, q.xb + k);
        hn::StoreU(hn::Mul(hn::Mul(hn::Set(d, s.qyy), dy), dy), d, q.i0 + k);
        hn::StoreU(hn::Mul(hn::Set(d, 2.f * s.qxy), dy), d, q.i1 + k);
        if (!s.exactIndex) continue;
        hn::StoreU(hn::MulAdd(dy, hn::MulAdd(hn::Set(d, s.map.wyy), dy, hn::Set(d, s.map.wy)), hn::Set(d, s.map.w0)), d, q.w0 + k);
        hn::StoreU(hn::MulAdd(hn::Set(d, s.map.wxy), dy, hn::Set(d, s.map.wx)), d, q.w1 + k);
    }
}

/// One row, one vector per n pixels of its chord, the first starting at the chord's first pixel
/// (a chord of up to n pixels is one vector wherever it lies; aligned starts took two for most
/// chords of a close-up's splats). A vector that would run past the row's end is moved back
/// inside it, and its lanes the previous vector drew are masked off. The rows come prepared
/// (SetUpRows): a vector costs its pixels' quadratics, the footprint and the deposit.
template <Sink kSink>
void DrawRowsWide(const SplatRaster& s, const TileBuffers& tile) {
    const hn::CappedTag<float, kStride> d;
    const int n = int(hn::Lanes(d));
    using V = hn::Vec<decltype(d)>;
    RowQuadratics q;
    SetUpRows(d, s, tile, q);
    const V lane = hn::Iota(d, 0.5f);  // pixel centre offsets 0.5, 1.5, …
    const V one = hn::Set(d, 1.f), eps = hn::Set(d, s.epsilon), qxx = hn::Set(d, s.qxx);
    const V wxx = hn::Set(d, s.map.wxx);
    const V cx = hn::Set(d, s.cx);
    const V rgb[3] = {hn::Set(d, s.color.x), hn::Set(d, s.color.y), hn::Set(d, s.color.z)};
    const int rows = s.y1 - s.y0 + 1;
    const uint32_t kLaneBits = uint32_t((uint64_t(1) << n) - 1);
    for (int k = 0; k < rows; ++k) {
        const int xa = q.xa[k], xb = q.xb[k];
        if (xa > xb) continue;
        const V i0 = hn::Set(d, q.i0[k]), i1 = hn::Set(d, q.i1[k]);
        const int row = (s.y0 + k - tile.y0) * kStride;
        // The chord's pixels not yet drawn, one bit per tile column (0 ≤ xa ≤ xb < kStride).
        uint32_t left = uint32_t((uint64_t(2) << xb) - (uint64_t(1) << xa));
        while (left != 0) {
            const int from = std::countr_zero(left);
            const int c = std::min(from, kStride - n);  // the vector's first pixel, inside the row
            // Lanes [from − c, xb − c]: the chord's pixels the previous vector has not drawn.
            const uint32_t lanes = (left >> c) & kLaneBits;
            left &= ~(kLaneBits << c);
            uint8_t laneBytes[8] = {uint8_t(lanes), uint8_t(lanes >> 8)};
            const auto chord = hn::LoadMaskBits(d, laneBytes);
            const V dx = hn::Sub(hn::Add(hn::Set(d, float(tile.x0 + c)), lane), cx);  // pixel centre − cx
            const V i2 = hn::MulAdd(hn::MulAdd(qxx, dx, i1), dx, i0);
            float* pt = tile.T + row + c;
            const V T = hn::LoadU(d, pt);
            const auto mask = hn::And(chord, hn::And(hn::Lt(i2, one), hn::Ge(T, eps)));
            if (hn::AllFalse(d, mask)) continue;
            const V tau = Tau(d, s, i2, [&] { return hn::MulAdd(hn::MulAdd(wxx, dx, hn::Set(d, q.w1[k])), dx, hn::Set(d, q.w0[k])); });
            Deposit<kSink>(d, s, tile, tau, T, mask, rgb, [&](const float* base) { return hn::LoadU(d, base + row + c); },
                            [&](float* base, V v) { hn::StoreU(v, d, base + row + c); });
        }
    }
}

#if HWY_TARGET != HWY_SCALAR
/// What DrawRowPairs needs of the rows y0 … y0 + 15 of a splat in a tile (lane k: row y0 + k),
/// set up once per splat and tile: the rows with a chord are [first, first + count); each one's
/// dy, offset in the tile, the image x of its 8-pixel window, and which of the window's 8 pixels
/// lie on its chord [xa, xb] (bit j: pixel start + j).
struct RowWindows {
    static constexpr int kMax = kPairLanes;
    alignas(64) float dy[kMax];       ///< pixel centre y − cy
    alignas(64) float xBase[kMax];    ///< float(image x of the window's first pixel)
    alignas(64) int32_t offset[kMax]; ///< (y − tile.y0)·stride + window start
    alignas(64) int32_t bits[kMax];   ///< the chord's pixels in the window
    int first = 0, count = 0;
};

/// A small splat on a 16-lane target: every row's chord fits in 8 pixels, so two rows share one
/// vector (the lower half one row's 8 pixels from its chord's start, the upper half the next
/// row's): half the vectors of DrawRowsWide, whose one vector per row leaves most lanes idle
/// for a splat a few pixels wide. Same per-pixel operations, so the same values. The rows' dy,
/// window positions and chord masks come prepared (RowWindows), so a pair costs two broadcasts
/// and a mask load before the footprint.
template <Sink kSink, class D>
void DrawRowPairs(D d, const SplatRaster& s, const TileBuffers& tile, const RowWindows& w) {
    using V = hn::Vec<D>;
    const hn::Half<D> dh;
    const V lanes = hn::Combine(d, hn::Iota(dh, 0.5f), hn::Iota(dh, 0.5f));  // pixel centre offsets, per half
    const V one = hn::Set(d, 1.f), eps = hn::Set(d, s.epsilon), cx = hn::Set(d, s.cx);
    const V rgb[3] = {hn::Set(d, s.color.x), hn::Set(d, s.color.y), hn::Set(d, s.color.z)};
    const int end = w.first + w.count;
    for (int k = w.first; k < end; k += 2) {
        const bool pair = k + 1 < end;
        const int ka = k, kb = pair ? k + 1 : k;  // a lone last row: its upper half repeats it, masked off
        const auto both = [&](const float* a) { return hn::Combine(d, hn::Set(dh, a[kb]), hn::Set(dh, a[ka])); };
        const V xPix = hn::Add(both(w.xBase), lanes);  // pixel centres
        const V dx = hn::Sub(xPix, cx);
        const V dy = both(w.dy);
        const V i2 = IndexSquared(d, s, dx, dy);
        const int offA = w.offset[ka], offB = w.offset[kb];
        const auto load = [&](const float* base) { return hn::Combine(d, hn::LoadU(dh, base + offB), hn::LoadU(dh, base + offA)); };
        const V T = load(tile.T);
        const uint8_t chord[8] = {uint8_t(w.bits[ka]), uint8_t(pair ? w.bits[kb] : 0)};
        const auto mask = hn::And(hn::LoadMaskBits(d, chord), hn::And(hn::Lt(i2, one), hn::Ge(T, eps)));
        if (hn::AllFalse(d, mask)) continue;
        const auto store = [&](float* base, V value) {
            hn::StoreU(hn::LowerHalf(dh, value), dh, base + offA);
            if (pair) hn::StoreU(hn::UpperHalf(dh, value), dh, base + offB);
        };
        const V tau = Tau(d, s, i2, [&] { return MapW(d, s.map, dx, dy); });
        Deposit<kSink>(d, s, tile, tau, T, mask, rgb, load, store);
    }
}

/// A splat whose pixel box in the tile is at most 8 columns wide (most splats of a framed view):
/// every row's 8-pixel window starts at the box's first column, so two rows share a vector as in
/// DrawRowPairs with nothing set up per row: the mask i² < 1 alone picks the ellipse's pixels (the
/// chord would only skip lanes it rejects). Per splat, dx and the i² terms in dx alone are fixed:
/// i² = Qxx dx² + (2 Qxy dx + Qyy dy)·dy, two FMAs a vector.
template <Sink kSink, class D>
void DrawBoxPairs(D d, const SplatRaster& s, const TileBuffers& tile) {
    using V = hn::Vec<D>;
    const hn::Half<D> dh;
    constexpr int kHalf = kPairLanes / 2;
    const int start = std::min(s.x0 - tile.x0, kStride - kHalf);  // the window's first column
    const V xPix = hn::Add(hn::Set(d, float(tile.x0 + start)), hn::Combine(d, hn::Iota(dh, 0.5f), hn::Iota(dh, 0.5f)));
    const V dx = hn::Sub(xPix, hn::Set(d, s.cx));
    const V ixx = hn::Mul(hn::Mul(hn::Set(d, s.qxx), dx), dx), ixy = hn::Mul(hn::Set(d, 2.f * s.qxy), dx);
    // The exact index's w in the same form (MapW's parts in dx alone, fixed per splat), set up
    // only for the splats that read it.
    V wAlongX = hn::Zero(d), wCross = wAlongX, wyy = wAlongX;
    if (s.exactIndex) wAlongX = WAlongX(d, s.map, dx), wCross = WCross(d, s.map, dx), wyy = hn::Set(d, s.map.wyy);
    const V qyy = hn::Set(d, s.qyy), cy = hn::Set(d, s.cy);
    const V one = hn::Set(d, 1.f), eps = hn::Set(d, s.epsilon);
    const V rgb[3] = {hn::Set(d, s.color.x), hn::Set(d, s.color.y), hn::Set(d, s.color.z)};
    // The box's columns, in each half; a lone last row keeps the lower half only.
    const auto columns = hn::And(hn::Ge(xPix, hn::Set(d, float(s.x0))), hn::Lt(xPix, hn::Set(d, float(s.x1 + 1))));
    const auto lowerHalf = hn::FirstN(d, size_t(kHalf));
    // Rows y and y + 1 (offsets off and off + stride in the tile), or a lone last row: its upper
    // half repeats it, masked off, and only the lower half is stored.
    const auto rows = [&](auto pairTag, V yPix, int off) {
        constexpr bool kPair = decltype(pairTag)::value;
        const int offB = kPair ? off + kStride : off;
        const V dy = hn::Sub(yPix, cy);  // float(y) + 0.5 − cy, as every loop computes it
        const V i2 = hn::MulAdd(hn::MulAdd(qyy, dy, ixy), dy, ixx);
        const auto load = [&](const float* base) { return hn::Combine(d, hn::LoadU(dh, base + offB), hn::LoadU(dh, base + off)); };
        const V T = load(tile.T);
        const auto mask = hn::And(kPair ? columns : hn::And(columns, lowerHalf), hn::And(hn::Lt(i2, one), hn::Ge(T, eps)));
        if (hn::AllFalse(d, mask)) return;
        const auto store = [&](float* base, V value) {
            hn::StoreU(hn::LowerHalf(dh, value), dh, base + off);
            if constexpr (kPair) hn::StoreU(hn::UpperHalf(dh, value), dh, base + offB);
        };
        const V tau = Tau(d, s, i2, [&] { return hn::MulAdd(hn::MulAdd(wyy, dy, wCross), dy, wAlongX); });
        Deposit<kSink>(d, s, tile, tau, T, mask, rgb, load, store);
    };
    V yPix = hn::Add(hn::Set(d, float(s.y0) + 0.5f), hn::Combine(d, hn::Set(dh, 1.f), hn::Zero(dh)));  // rows y, y + 1
    const V two = hn::Set(d, 2.f);
    int y = s.y0, off = (s.y0 - tile.y0) * kStride + start;
    for (; y < s.y1; y += 2, off += 2 * kStride, yPix = hn::Add(yPix, two)) rows(std::true_type(), yPix, off);
    if (y == s.y1) rows(std::false_type(), yPix, off);
}

/// Every row's chord at once (SetUpRows' arithmetic, one lane per row of the splat's rows in the
/// tile), and from them, in the same lanes, each row's 8-pixel window and chord mask; if the rows
/// with a chord are one run (they are: an ellipse is convex) and every chord fits its window,
/// draws them two by two (DrawRowPairs) and returns true.
template <Sink kSink, class D>
bool DrawRowPairsIfNarrow(D d, const SplatRaster& s, const TileBuffers& tile) {
    constexpr int kHalf = kPairLanes / 2;
    const hn::RebindToSigned<D> di;
    using VI = hn::Vec<decltype(di)>;
    RowWindows w;
    const auto dy = hn::Sub(hn::Iota(d, float(s.y0) + 0.5f), hn::Set(d, s.cy));  // float(y) + 0.5 − cy
    hn::Store(dy, d, w.dy);
    const auto b = hn::Mul(hn::Set(d, s.qxy), dy);
    const auto disc = hn::Sub(hn::Mul(b, b), hn::Mul(hn::Set(d, s.qxx), hn::Sub(hn::Mul(hn::Mul(hn::Set(d, s.qyy), dy), dy), hn::Set(d, 1.f))));
    const auto has = hn::And(hn::Gt(disc, hn::Zero(d)), hn::FirstN(d, size_t(s.y1 - s.y0 + 1)));
    const auto root = hn::Sqrt(hn::Max(disc, hn::Zero(d)));
    // One reciprocal instead of two vector divisions: the chord keeps a pixel of slack each
    // side (floor, ceil) and the mask's i² < 1 decides every pixel, so a last-bit difference
    // in lo or hi draws the same pixels with the same values.
    const auto base = hn::Set(d, s.cx - 0.5f), invQxx = hn::Set(d, 1.f / s.qxx);
    const auto lo = hn::MulAdd(hn::Sub(hn::Neg(b), root), invQxx, base);
    const auto hi = hn::MulAdd(hn::Sub(root, b), invQxx, base);
    const VI xa = hn::ConvertTo(di, hn::Max(hn::Floor(lo), hn::Set(d, float(s.x0))));
    const VI xb = hn::ConvertTo(di, hn::Min(hn::Ceil(hi), hn::Set(d, float(s.x1))));
    const auto onChord = hn::And(has, hn::RebindMask(d, hn::Lt(xa, hn::Add(xb, hn::Set(di, 1)))));
    uint8_t chordBits[8] = {};
    hn::StoreMaskBits(d, onChord, chordBits);
    const unsigned rows = unsigned(chordBits[0]) | unsigned(chordBits[1]) << 8;
    if (rows == 0) return true;  // nothing of the splat in this tile
    w.first = std::countr_zero(rows);
    const unsigned run = rows >> w.first;
    if ((run & (run + 1)) != 0) return false;  // not one run (a last-bit case): the row loop
    w.count = std::popcount(rows);
    const VI width = hn::Sub(xb, xa);  // pixels − 1
    if (!hn::AllFalse(di, hn::And(hn::RebindMask(di, onChord), hn::Gt(width, hn::Set(di, kHalf - 1))))) return false;
    // [start, start + 8) ⊇ [xa, xb] − x0, inside the row; pixel x is on the chord iff
    // xa ≤ x ≤ xb (the mask xa ≤ x + ½ < xb + ¾ of DrawRowsWide).
    const VI rel = hn::Sub(xa, hn::Set(di, tile.x0));
    const VI start = hn::Min(rel, hn::Set(di, kStride - kHalf));
    const VI row = hn::Iota(di, s.y0 - tile.y0);
    hn::Store(hn::Add(hn::Mul(row, hn::Set(di, kStride)), start), di, w.offset);
    hn::Store(hn::ConvertTo(d, hn::Add(start, hn::Set(di, tile.x0))), d, w.xBase);
    const VI ones = hn::Set(di, 1);
    const VI run8 = hn::Sub(hn::Shl(ones, hn::Add(width, ones)), ones);  // width + 1 low bits (≤ 8)
    hn::Store(hn::Shl(run8, hn::Sub(rel, start)), di, w.bits);
    DrawRowPairs<kSink>(d, s, tile, w);
    return true;
}

#endif  // HWY_TARGET != HWY_SCALAR

// The sink is a template argument (Sink), so each loop is the code it would be alone.
template <Sink kSink, class D>
void DrawSplatRowsFor(D d, const SplatRaster& s, const TileBuffers& tile) {
#if HWY_TARGET != HWY_SCALAR
    // Splats up to 16 rows tall in the tile whose every chord fits 8 pixels: two rows a vector.
    if constexpr (hn::MaxLanes(D()) == kPairLanes) {
        if (s.x1 - s.x0 < kPairLanes / 2) return DrawBoxPairs<kSink>(d, s, tile);
        if (s.y1 - s.y0 + 1 <= kPairLanes && DrawRowPairsIfNarrow<kSink>(d, s, tile)) return;
    }
#else
    (void)d;
#endif
    DrawRowsWide<kSink>(s, tile);
}

void DrawSplatRows(const SplatRaster& s, const TileBuffers& tile) {
    const hn::CappedTag<float, kPairLanes> d;
    if (s.slabs) return s.slabs->eg[0] ? DrawSplatRowsFor<Sink::Slabs>(d, s, tile) : DrawSplatRowsFor<Sink::SlabsGrey>(d, s, tile);
    if (!tile.G) return DrawSplatRowsFor<Sink::OverGrey>(d, s, tile);
    DrawSplatRowsFor<Sink::Over>(d, s, tile);
}

/// One slab over the live pixels of the tile's rectangle, then emptied there (compositeSlabVector):
/// each row's vectors from the one holding the rectangle's first column (row starts are aligned).
template <bool kGrey>
void CompositeSlabFor(float* tau, float* er, float* eg, float* eb, const TileBuffers& tile, float epsilon, TileRect rect) {
    const hn::CappedTag<float, kStride> d;
    using V = hn::Vec<decltype(d)>;
    const int n = int(hn::Lanes(d));
    const V zero = hn::Zero(d), eps = hn::Set(d, epsilon);
    const int first = rect.x0 / n * n;
    for (int y = rect.y0; y <= rect.y1; ++y)
        for (int i = y * kStride + first, end = y * kStride + rect.x1; i <= end; i += n) {
            const V t = hn::Load(d, tau + i);
            const V T = hn::Load(d, tile.T + i);
            const auto mask = hn::And(hn::Gt(t, zero), hn::Ge(T, eps));
            if (!hn::AllFalse(d, mask)) {
                V ta = hn::Mul(T, OpacityFromTau(d, t));  // T·α
                V next = hn::Sub(T, ta);
                TakeRemainder(d, T, epsilon, ta, next);
                const V w = hn::IfThenElseZero(mask, hn::Div(ta, hn::IfThenElse(mask, t, hn::Set(d, 1.f))));
                hn::Store(hn::MulAdd(w, hn::Load(d, er + i), hn::Load(d, tile.R + i)), d, tile.R + i);
                if constexpr (!kGrey) {
                    hn::Store(hn::MulAdd(w, hn::Load(d, eg + i), hn::Load(d, tile.G + i)), d, tile.G + i);
                    hn::Store(hn::MulAdd(w, hn::Load(d, eb + i), hn::Load(d, tile.B + i)), d, tile.B + i);
                }
                hn::Store(hn::IfThenElse(mask, next, T), d, tile.T + i);
            }
            hn::Store(zero, d, tau + i), hn::Store(zero, d, er + i);
            if constexpr (!kGrey) hn::Store(zero, d, eg + i), hn::Store(zero, d, eb + i);
        }
}

/// The slab over the tile's four channels, or (no G, B and no green and blue sums) over T and R alone.
void CompositeSlab(float* tau, float* er, float* eg, float* eb, const TileBuffers& tile, float epsilon, TileRect rect) {
    if (!tile.G) return CompositeSlabFor<true>(tau, er, eg, eb, tile, epsilon, rect);
    CompositeSlabFor<false>(tau, er, eg, eb, tile, epsilon, rect);
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(DrawSplatRows);
HWY_EXPORT(CompositeSlab);

void compositeSlabVector(float* tau, float* er, float* eg, float* eb, const TileBuffers& tile, float epsilon, TileRect rect) {
    HWY_DYNAMIC_DISPATCH(CompositeSlab)(tau, er, eg, eb, tile, epsilon, rect);
}

void drawSplatVector(const SplatRaster& s, const TileBuffers& tile) { HWY_DYNAMIC_DISPATCH(DrawSplatRows)(s, tile); }

void drawSplatScalarPoly(const SplatRaster& s, const TileBuffers& tile) {
    constexpr int kStride = kTileSize;
    for (int y = s.y0; y <= s.y1; ++y) {
        const float dy = float(y) + 0.5f - s.cy;
        for (int x = s.x0; x <= s.x1; ++x) {
            const int i = (y - tile.y0) * kStride + (x - tile.x0);
            if (!(tile.T[i] >= s.epsilon)) continue;
            const float dx = float(x) + 0.5f - s.cx;
            const float i2 = s.qxx * dx * dx + 2.f * s.qxy * dx * dy + s.qyy * dy * dy;
            if (!(i2 < 1.f)) continue;
            const float t = s.exactIndex ? s.map.d2(i2, dx, dy) : i2;
            const float tau = s.scale * FootprintPolynomials::evaluate(s.coef, t);
            if (s.slabs) {
                for (int j = 0; j < s.slabs->count; ++j) {
                    const float tj = tau * s.slabs->fraction[size_t(j)];
                    s.slabs->tau[size_t(j)][i] += tj;
                    s.slabs->er[size_t(j)][i] += tj * s.color.x;
                    if (!s.slabs->eg[size_t(j)]) continue;  // one channel
                    s.slabs->eg[size_t(j)][i] += tj * s.color.y;
                    s.slabs->eb[size_t(j)][i] += tj * s.color.z;
                }
                continue;
            }
            const float ta = takeTransmittance(tile.T[i], opacityFromOpticalDepth(tau), s.epsilon);
            tile.R[i] += ta * s.color.x;
            if (tile.G) tile.G[i] += ta * s.color.y, tile.B[i] += ta * s.color.z;  // else one channel
        }
    }
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
