// volume/leaf_extract.cpp — extractLeafVoxels with Google Highway (see leaf_extract.h). Compiled
// once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volume/leaf_extract.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "volume/classify-inl.h"
#include "volume/leaf_extract.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

bool LeafExtractSupported() { return WholeRowsSupported(hn::ScalableTag<float>()); }

/// The records of one leaf, a vector of rows at a time. The view position splits as glm computes
/// it, v = (m₀X + m₁Y) + (m₂Z + m₃): the second sum depends on z alone, so it is one vector per
/// half-vector of lanes for the whole leaf, and the first is a scalar per row; the positions are
/// in double on half as many lanes, then rounded to float as the scalar path's casts do.
template <class D>
size_t ExtractRows(D d, const float* values, const uint64_t* maskWords, const ClassificationTable& table,
                   const glm::dmat4& M, const glm::ivec3& origin, const LeafRecords& out, const LeafFactors* factors) {
#if HWY_TARGET != HWY_SCALAR
    if constexpr (kWholeRows<D>) {
        using V = hn::Vec<D>;
        const hn::Repartition<double, D> dd;     // half the lanes, in double
        using VD = hn::Vec<decltype(dd)>;
        const hn::Rebind<float, decltype(dd)> dh;  // float, half the lanes
        const hn::RebindToSigned<decltype(dd)> dl;
        const int lanes = int(hn::Lanes(d)), halfLanes = lanes / 2, rowsPerVector = lanes / 8;
        const ClassifyLanes<D> classify(d, table);
        // Per half h of a vector: its lanes' row within the vector and m₂Z + m₃ (Z = origin.z + z).
        int rowOf[2];
        VD zPart[2][3];
        for (int h = 0; h < 2; ++h) {
            rowOf[h] = (h * halfLanes) >> 3;
            const VD z = hn::Add(hn::ConvertTo(dd, hn::And(hn::Iota(dl, h * halfLanes), hn::Set(dl, 7))), hn::Set(dd, double(origin.z)));
            for (int c = 0; c < 3; ++c) zPart[h][c] = hn::Add(hn::Mul(hn::Set(dd, M[2][c]), z), hn::Set(dd, M[3][c]));
        }
        const auto toFloat = [&](VD lo, VD hi) { return hn::Combine(d, hn::DemoteTo(dh, hi), hn::DemoteTo(dh, lo)); };
        const V zero = hn::Zero(d);
        static_assert(hn::MaxLanes(D()) <= kLeafRecordSlack, "a vector of records fits the slack");
        size_t k = 0;
        for (int x = 0; x < 8; ++x) {
            const double X = double(origin.x) + double(x);
            for (int y = 0; y < 8; y += rowsPerVector) {
                const int n = x * 64 + y * 8;
                const V value = hn::LoadU(d, values + n);
                const auto active = ActiveLanes(d, value, maskWords, n);
                if (hn::AllFalse(d, active)) continue;
                const V index = classify.Index(value, active);
                if (classify.AllTransparent(index)) continue;
                V sigma, red, green, blue;
                classify(index, active, sigma, red, green, blue);
                ApplyFactors(d, factors, n, sigma, red, green, blue);
                const auto keep = hn::Gt(sigma, zero);  // 0 where inactive
                if (hn::AllFalse(d, keep)) continue;
                VD p[2][3], dist[2];
                for (int h = 0; h < 2; ++h) {
                    const double Y = double(origin.y) + double(y + rowOf[h]);
                    for (int c = 0; c < 3; ++c) p[h][c] = hn::Add(hn::Set(dd, M[0][c] * X + M[1][c] * Y), zPart[h][c]);
                    dist[h] = hn::Sqrt(hn::Add(hn::Add(hn::Mul(p[h][0], p[h][0]), hn::Mul(p[h][1], p[h][1])), hn::Mul(p[h][2], p[h][2])));
                }
                const size_t count = hn::CountTrue(d, keep);
                // The kept lanes first, stored whole: the lanes past `count` land in the records
                // the next vector overwrites, or in the slack (kLeafRecordSlack). Staged aside and
                // copied by their count, the copy was a `rep movsq` per array and vector, ~40 % of
                // this loop (docs/performance.md, session 38).
                const auto stage3 = [&](V a, V b, V c, glm::vec3* to) {
                    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "vec3 is three packed floats");
                    hn::StoreInterleaved3(hn::Compress(a, keep), hn::Compress(b, keep), hn::Compress(c, keep), d,
                                          reinterpret_cast<float*>(to + k));
                };
                const auto stage1 = [&](V a, float* to) { hn::StoreU(hn::Compress(a, keep), d, to + k); };
                stage3(toFloat(p[0][0], p[1][0]), toFloat(p[0][1], p[1][1]), toFloat(p[0][2], p[1][2]), out.viewPos);
                stage1(toFloat(dist[0], dist[1]), out.distance);
                stage1(sigma, out.sigma);
                stage3(red, green, blue, out.color);
                k += count;
            }
        }
        return k;
    } else
#endif
    {
        (void)d, (void)values, (void)maskWords, (void)table, (void)M, (void)origin, (void)out, (void)factors;
        return 0;
    }
}

size_t ExtractLeafVoxelsImpl(const float* values, const uint64_t* maskWords, const ClassificationTable& table,
                             const glm::dmat4& indexToView, const glm::ivec3& origin, const LeafRecords& out,
                             const LeafFactors* factors) {
    return ExtractRows(hn::ScalableTag<float>(), values, maskWords, table, indexToView, origin, out, factors);
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(ExtractLeafVoxelsImpl);
HWY_EXPORT(LeafExtractSupported);

bool leafExtractSupported() { return HWY_DYNAMIC_DISPATCH(LeafExtractSupported)(); }

size_t extractLeafVoxels(const float* values, const uint64_t* maskWords, const ClassificationTable& table,
                         const glm::dmat4& indexToView, const glm::ivec3& origin, const LeafRecords& out,
                         const LeafFactors* factors) {
    return HWY_DYNAMIC_DISPATCH(ExtractLeafVoxelsImpl)(values, maskWords, table, indexToView, origin, out, factors);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
