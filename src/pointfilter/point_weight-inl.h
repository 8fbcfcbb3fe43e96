// pointfilter/point_weight-inl.h — pointFilterWeight on every lane of a Highway vector,
// with its float operations. Shared by the point setup
// (pointfilter/point_setup.cpp) and the point loop (composite/point_raster.cpp); included once
// per SIMD target from inside their foreach_target.h passes (Highway's per-target include
// guard), after <hwy/highway.h>. Compile the including file with -ffp-contract=off: the scalar
// pointFilterWeight() is the oracle, bit for bit.
#if defined(VDBSPLAT_POINT_WEIGHT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef VDBSPLAT_POINT_WEIGHT_INL_H_
#undef VDBSPLAT_POINT_WEIGHT_INL_H_
#else
#define VDBSPLAT_POINT_WEIGHT_INL_H_
#endif

#include <hwy/highway.h>

#include "pointfilter/point_filter.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {

/// pointFilterWeight on every lane: 0 where !(x < maxX) (NaN too); else 2^n·P(f), the
/// scalar pointFilterWeight()'s products and sums in the same order (no MulAdd: the same floats on every target).
template <class D, class V = hwy::HWY_NAMESPACE::Vec<D>>
HWY_INLINE V PointWeight(D d, V x) {
    namespace hn = hwy::HWY_NAMESPACE;
    namespace pfw = vdbsplat::point_filter_weight;
    const hn::RebindToSigned<D> di;
    constexpr int kDegree = pfw::kDegree;
    const auto valid = hn::Lt(x, hn::Set(d, pfw::maxX()));  // false for NaN
    const V y = hn::Mul(hn::Max(hn::IfThenElseZero(valid, x), hn::Zero(d)), hn::Set(d, pfw::kYPerX));
    const V n = hn::Round(y);
    const V f = hn::Sub(y, n);
    // pfw::pow2Fraction's operations, in its order (Estrin's scheme).
    static_assert(kDegree == 6, "pow2Fraction's degree");
    const auto c = [&](int k) { return hn::Set(d, pfw::kPow2[size_t(k)]); };
    const V f2 = hn::Mul(f, f), f4 = hn::Mul(f2, f2);
    const V a = hn::Add(c(0), hn::Mul(c(1), f)), b = hn::Add(c(2), hn::Mul(c(3), f)), e = hn::Add(c(4), hn::Mul(c(5), f));
    const V p = hn::Add(hn::Add(a, hn::Mul(f2, b)), hn::Mul(f4, hn::Add(e, hn::Mul(f2, c(6)))));
    const V scale = hn::BitCast(d, hn::ShiftLeft<23>(hn::Add(hn::ConvertTo(di, n), hn::Set(di, 127))));
    return hn::IfThenElseZero(valid, hn::Mul(p, scale));
}

/// A point's eight columns from pixel @p firstX and eight rows from @p firstY, in one set of 16
/// lanes (lanes 0–7 the columns, 8–15 the rows: one PointWeight for a 16-lane target): each
/// pixel centre's squared offset from the point's centre (@p cx, @p cy), (i + ½) − c in float (one
/// rounding of the exact difference, as the scalar setup's double difference rounded to float is),
/// into @p sq, and its weight PointWeight(offset² / V) into @p g. The point setup and the point
/// loops share it, so their weights are the same floats.
HWY_INLINE void AxisWeights(int firstX, int firstY, float cx, float cy, float invVariance,
                            float* HWY_RESTRICT sq, float* HWY_RESTRICT g) {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::CappedTag<float, 16> d;
    const hn::RebindToSigned<decltype(d)> di;
    constexpr int N = int(hn::MaxLanes(d));
    for (int k = 0; k < 16; k += N) {
        const auto lane = hn::Iota(di, k);
        const auto isX = hn::Lt(lane, hn::Set(di, 8));
        const auto pixel = hn::IfThenElse(isX, hn::Add(lane, hn::Set(di, firstX)), hn::Add(lane, hn::Set(di, firstY - 8)));
        const auto centre = hn::IfThenElse(hn::RebindMask(d, isX), hn::Set(d, cx), hn::Set(d, cy));
        const auto off = hn::Sub(hn::Add(hn::ConvertTo(d, pixel), hn::Set(d, 0.5f)), centre);
        const auto off2 = hn::Mul(off, off);
        hn::Store(off2, d, sq + k);
        hn::Store(PointWeight(d, hn::Mul(off2, hn::Set(d, invVariance))), d, g + k);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#endif  // VDBSPLAT_POINT_WEIGHT_INL_H_
