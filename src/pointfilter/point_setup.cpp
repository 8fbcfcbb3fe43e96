// pointfilter/point_setup.cpp — setupPoint's footprint sum with Google Highway (see
// point_filter.h, setupPointVector). Compiled once per SIMD target (foreach_target.h);
// HWY_DYNAMIC_DISPATCH picks the best the CPU supports at run time. Built with
// -ffp-contract=off (CMakeLists.txt): the scalar setup is the oracle, bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "pointfilter/point_setup.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "pointfilter/point_weight-inl.h"

#include "pointfilter/point_filter.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;


PointSetup SetupPoint(const PixelCoord& x, double variance) {
    PointSetup s;
    float invV = 0.0f, rs2 = 0.0f;
    if (!pointSetupBox(x, variance, s, invV, rs2)) return s;
    // Lanes 0–7: the columns' squared offsets and weights; 8–15: the rows'.
    alignas(64) float sq[16], g[16];
    AxisWeights(s.x0, s.y0, float(x.x), float(x.y), invV, sq, g);
    // Each column's sum down the rows in a lane (0 outside the circle and past nx; adding +0
    // changes no sum), then the columns pairwise: sumColumnsPairwise's order, as setupPoint's.
    const hn::CappedTag<float, kPointSumColumns> d8;
    constexpr int N8 = int(hn::MaxLanes(d8));
    alignas(64) float columns[kPointSumColumns];
    for (int k = 0; k < kPointSumColumns; k += N8) {
        const auto gx = hn::Load(d8, g + k), dx2 = hn::Load(d8, sq + k);
        const auto cols = hn::RebindMask(d8, hn::Lt(hn::Iota(hn::RebindToSigned<decltype(d8)>(), k),
                                                    hn::Set(hn::RebindToSigned<decltype(d8)>(), s.nx)));
        auto acc = hn::Zero(d8);
        for (int iy = 0; iy < s.ny; ++iy) {
            const auto in = hn::And(cols, hn::Lt(hn::Add(dx2, hn::Set(d8, sq[8 + iy])), hn::Set(d8, rs2)));
            acc = hn::Add(acc, hn::IfThenElseZero(in, hn::Mul(gx, hn::Set(d8, g[8 + iy]))));
        }
        hn::Store(acc, d8, columns + k);
    }
    const float sum = sumColumnsPairwise(columns);
    finishPointSetup(s, x, sum, invV, rs2);
    return s;
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(SetupPoint);

PointSetup setupPointVector(const PixelCoord& x, double variance) {
    return HWY_DYNAMIC_DISPATCH(SetupPoint)(x, variance);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
