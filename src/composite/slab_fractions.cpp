// composite/slab_fractions.cpp — slabFractionsBatch with Google Highway (see slab_profile.h):
// the slab fractions of many primitives, one lane each. Compiled once per SIMD target
// (foreach_target.h), and without contraction (CMakeLists.txt): every expression is the scalar
// slabFractionsOf's and MarginalCdfTable's (slab_profile.{h,cpp}), operation for operation, so the
// fractions are the scalar ones bit for bit — the scalar path stays the oracle (tested).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite/slab_fractions.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>

#include "composite/slab_profile.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// MarginalCdfTable::operator() at the lanes of @p x.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Cdf(D d, const MarginalCdfTable& cdf, V x) {
    const hn::RebindToSigned<D> di;
    const V intervals = hn::Set(d, double(MarginalCdfTable::kIntervals));
    const V u = hn::Mul(hn::Add(x, hn::Set(d, cdf.radius())), hn::Set(d, cdf.scale()));
    const V v = hn::IfThenElseZero(hn::And(hn::Gt(u, hn::Zero(d)), hn::Lt(u, intervals)), u);
    const auto i = hn::ConvertTo(di, v);  // v in [0, kIntervals): truncation is int(v)
    const V t = hn::Sub(v, hn::ConvertTo(d, i));
    // The table's pairs read lane by lane: Zen 4's gathers took a quarter of the function's time.
    HWY_ALIGN int64_t index[hn::MaxLanes(d)];
    HWY_ALIGN double a[hn::MaxLanes(d)], b[hn::MaxLanes(d)];
    hn::Store(i, di, index);
    const double* values = cdf.values();
    for (size_t k = 0; k < hn::Lanes(d); ++k) a[k] = values[index[k]], b[k] = values[index[k] + 1];
    const V lo = hn::Load(d, a), hi = hn::Load(d, b);
    const V c = hn::Add(lo, hn::Mul(t, hn::Sub(hi, lo)));
    return hn::IfThenElse(hn::Ge(u, intervals), hn::Set(d, 1.0), c);
}

void SlabFractionsBatch(const MarginalCdfTable& cdf, const double* offset, const double* unitInSlabs, const int* lowest,
                        size_t n, int reach, SlabProfile* out) {
    const hn::ScalableTag<double> d;
    using V = hn::Vec<decltype(d)>;
    const size_t N = hn::Lanes(d);
    reach = std::clamp(reach, 0, kMaxSlabReach);
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0), tiny = hn::Set(d, 1e-12);
    HWY_ALIGN double offsetIn[hn::MaxLanes(d)], unitIn[hn::MaxLanes(d)], fractions[kMaxSlabSpan][hn::MaxLanes(d)];
    HWY_ALIGN double lowestIn[hn::MaxLanes(d)];  // small integers, exact as doubles
    HWY_ALIGN double sumOut[hn::MaxLanes(d)];
    for (size_t k0 = 0; k0 < n; k0 += N) {
        const size_t m = std::min(N, n - k0);
        for (size_t k = 0; k < N; ++k) {  // the lanes past n as a primitive at offset 0.5, unit 1
            offsetIn[k] = k < m ? offset[k0 + k] : 0.5;
            unitIn[k] = k < m ? unitInSlabs[k0 + k] : 1.0;
            lowestIn[k] = k < m ? double(lowest[k0 + k]) : double(-kMaxSlabReach);
        }
        const V off = hn::Load(d, offsetIn), unit = hn::Load(d, unitIn);
        // inv = 1 / std::max(unit, 1e-12): std::max keeps `unit` unless unit < 1e-12 (a NaN too)
        const V inv = hn::Div(one, hn::IfThenElse(hn::Lt(unit, tiny), tiny, unit));
        const V first = hn::Max(hn::Load(d, lowestIn), hn::Set(d, double(-reach)));
        // C at the slab boundaries m − offset (m = −reach … reach + 1), each once: the scalar's
        // `hi` of slab r is computed at double(r) + 1.0, which is double(r + 1).
        V lo = Cdf(d, cdf, hn::Mul(hn::Sub(hn::Set(d, double(-reach)), off), inv));
        V sum = zero;
        for (int r = -reach; r <= reach; ++r) {
            const V hi = Cdf(d, cdf, hn::Mul(hn::Sub(hn::Set(d, double(r) + 1.0), off), inv));
            const V diff = hn::Sub(hi, lo);
            const V f0 = hn::IfThenElse(hn::Lt(diff, zero), zero, diff);  // std::max(hi − lo, 0.0)
            const auto taken = hn::Ge(hn::Set(d, double(r)), first);
            const V f = hn::IfThenElseZero(taken, f0);  // slabs before `first` hold 0 (+ 0 keeps the sum)
            sum = hn::Add(sum, f);
            hn::Store(f, d, fractions[size_t(r + reach)]);
            lo = hi;
        }
        const V invSum = hn::Div(one, sum);
        for (int j = 0; j <= 2 * reach; ++j) hn::Store(hn::Mul(hn::Load(d, fractions[size_t(j)]), invSum), d, fractions[size_t(j)]);
        hn::Store(sum, d, sumOut);
        for (size_t k = 0; k < m; ++k) {
            SlabProfile& p = out[k0 + k];
            p.fraction.fill(0.f);
            if (!(sumOut[k] > 0.0)) {  // nothing within reach: all in its own slab (as the scalar)
                p.fraction[size_t(reach)] = 1.f;
                continue;
            }
            for (int j = 0; j <= 2 * reach; ++j) p.fraction[size_t(j)] = float(fractions[size_t(j)][k]);
        }
    }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(SlabFractionsBatch);

void slabFractionsBatch(const MarginalCdfTable& cdf, const double* offset, const double* unitInSlabs, const int* lowest,
                        size_t n, int reach, SlabProfile* out) {
    HWY_DYNAMIC_DISPATCH(SlabFractionsBatch)(cdf, offset, unitInSlabs, lowest, n, reach, out);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
