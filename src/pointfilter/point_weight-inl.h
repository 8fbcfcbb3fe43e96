// pointfilter/point_weight-inl.h — PointFilterTable::weight on every lane of a Highway vector,
// with weight()'s float operations (two gathers). Shared by the point setup
// (pointfilter/point_setup.cpp) and the point loop (composite/point_raster.cpp); included once
// per SIMD target from inside their foreach_target.h passes (Highway's per-target include
// guard), after <hwy/highway.h>. Compile the including file with -ffp-contract=off: the scalar
// weight() is the oracle, bit for bit.
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

/// PointFilterTable::weight on every lane: 0 where !(x < maxX) (NaN too); else the linear lookup.
template <class D, class V = hwy::HWY_NAMESPACE::Vec<D>>
HWY_INLINE V PointWeight(D d, const PointFilterTable& table, V x) {
    namespace hn = hwy::HWY_NAMESPACE;
    const hn::RebindToSigned<D> di;
    const auto valid = hn::Lt(x, hn::Set(d, PointFilterTable::maxX()));  // false for NaN
    const V t = hn::Mul(hn::Max(hn::IfThenElseZero(valid, x), hn::Zero(d)), hn::Set(d, table.indexScale()));
    const auto k = hn::Min(hn::ConvertTo(di, t), hn::Set(di, PointFilterTable::kIntervals - 1));
    const V w = hn::Sub(t, hn::ConvertTo(d, k));
    const V v0 = hn::GatherIndex(d, table.values(), k), v1 = hn::GatherIndex(d, table.values() + 1, k);
    return hn::IfThenElseZero(valid, hn::Add(v0, hn::Mul(w, hn::Sub(v1, v0))));
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#endif  // VDBSPLAT_POINT_WEIGHT_INL_H_
