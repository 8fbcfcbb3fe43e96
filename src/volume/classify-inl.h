// volume/classify-inl.h — ClassificationTable::operator() on every lane of a Highway vector, with
// its float operations (x = clamp(v·scale + offset), i = min(⌊x⌋, size − 2), the entries i and
// i + 1 lerped by x − i), so the same values bit for bit. Shared by the level-of-detail moments
// (volume/leaf_moments.cpp) and the leaf extraction (volume/leaf_extract.cpp); included once per
// SIMD target from inside their foreach_target.h passes (Highway's per-target include guard),
// after <hwy/highway.h>. Targets whose vectors hold 8 or 16 floats (the callers' row layout).
#if defined(VDBSPLAT_CLASSIFY_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef VDBSPLAT_CLASSIFY_INL_H_
#undef VDBSPLAT_CLASSIFY_INL_H_
#else
#define VDBSPLAT_CLASSIFY_INL_H_
#endif

#include <hwy/highway.h>

#include "shading/shade_leaf.h"
#include "volume/transfer_function.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {

/// Vectors of whole 8-voxel rows (8 or 16 float lanes): each lane keeps its z from one vector to
/// the next. The leaf passes run on such targets only; others take the scalar paths.
template <class D>
constexpr bool kWholeRows = hwy::HWY_NAMESPACE::MaxLanes(D()) == 8 || hwy::HWY_NAMESPACE::MaxLanes(D()) == 16;

/// True when the target's vectors of @p D hold whole rows (as kWholeRows, and fully used).
template <class D>
bool WholeRowsSupported(D) {
    if constexpr (kWholeRows<D>) return hwy::HWY_NAMESPACE::Lanes(D()) == hwy::HWY_NAMESPACE::MaxLanes(D());
    return false;
}

#if HWY_TARGET != HWY_SCALAR
/// The baked table's constants as vectors, set up once per leaf; @p table must not be empty().
template <class D>
struct ClassifyLanes {
    using V = hwy::HWY_NAMESPACE::Vec<D>;
    static_assert(sizeof(Classified) == 4 * sizeof(float), "Classified is {vec3 colour, float σ}");
    D d;
    V scale, offset, zero, top, transparent;
    const double* pairs;        ///< the entries as pairs of floats: (r, g), (b, σ)
    const LinearPieces* pieces;  ///< the exact pieces, or nullptr: the entries

    ClassifyLanes(D tag, const ClassificationTable& table)
        : d(tag),
          scale(hwy::HWY_NAMESPACE::Set(tag, table.scale())),
          offset(hwy::HWY_NAMESPACE::Set(tag, table.offset())),
          zero(hwy::HWY_NAMESPACE::Zero(tag)),
          top(hwy::HWY_NAMESPACE::Set(tag, float(ClassificationTable::kSize - 1))),
          transparent(hwy::HWY_NAMESPACE::Set(tag, table.transparentBelow())),
          pairs(reinterpret_cast<const double*>(table.entries())),
          pieces(table.pieces().count ? &table.pieces() : nullptr) {}

    /// The lanes' table index x (0 where !active).
    template <class M>
    V Index(V value, M active) const {
        namespace hn = hwy::HWY_NAMESPACE;
        return hn::IfThenElseZero(active, hn::Min(hn::Max(hn::Add(hn::Mul(value, scale), offset), zero), top));
    }
    /// Every lane's σ is 0 exactly (both lerped entries have σ = 0): nothing to classify.
    bool AllTransparent(V x) const { return hwy::HWY_NAMESPACE::AllTrue(d, hwy::HWY_NAMESPACE::Lt(x, transparent)); }

    /// σ (0 where !active) and the colour of index @p x. Entries i and i + 1 by pairs of floats:
    /// (r, g) and (b, σ) are 8 bytes each, so 64-bit gathers fetch two channels at once (half the
    /// element loads of one 32-bit gather per channel and entry), and even/odd lanes split them.
    template <class M>
    void operator()(V x, M active, V& sigma, V& r, V& g, V& b) const {
        if (pieces) return Pieces(x, active, sigma, r, g, b);
        namespace hn = hwy::HWY_NAMESPACE;
        const hn::RebindToSigned<D> di;
        const hn::Repartition<double, D> dd;
        const hn::RebindToSigned<decltype(dd)> dl;
        const hn::Half<decltype(di)> dih;
        const auto i = hn::Min(hn::ConvertTo(di, x), hn::Set(di, ClassificationTable::kSize - 2));
        const V t = hn::Sub(x, hn::ConvertTo(d, i));
        const auto iLo = hn::PromoteTo(dl, hn::LowerHalf(dih, i)), iHi = hn::PromoteTo(dl, hn::UpperHalf(dih, i));
        const auto gather = [&](int64_t first, V& even, V& odd) {  // first: 0 (r, g), 1 (b, σ); +2: entry i + 1
            const V lo = hn::BitCast(d, hn::GatherIndex(dd, pairs, hn::Add(hn::ShiftLeft<1>(iLo), hn::Set(dl, first))));
            const V hi = hn::BitCast(d, hn::GatherIndex(dd, pairs, hn::Add(hn::ShiftLeft<1>(iHi), hn::Set(dl, first))));
            even = hn::ConcatEven(d, hi, lo), odd = hn::ConcatOdd(d, hi, lo);
        };
        V r0, g0, b0, s0, r1, g1, b1, s1;
        gather(0, r0, g0), gather(1, b0, s0), gather(2, r1, g1), gather(3, b1, s1);
        const auto lerp = [&](V lo, V hi) { return hn::Add(lo, hn::Mul(t, hn::Sub(hi, lo))); };
        sigma = hn::IfThenElseZero(active, lerp(s0, s1));
        r = lerp(r0, r1), g = lerp(g0, g1), b = lerp(b0, b1);
    }

    /// As operator(), by LinearPieces::operator() (x − knot[0] = x: knot[0] = 0). One piece: its
    /// numbers broadcast. More: each lane's piece j is its bucket's first
    /// piece, plus one for each following knot at or below x (knotsPerBucket compares); its knot,
    /// values and slopes are permuted out of the pieces' columns (one vector of 16, or two of 8
    /// and a blend); then value + slope · (x − knot).
    template <class M>
    void Pieces(V x, M active, V& sigma, V& r, V& g, V& b) const {
        namespace hn = hwy::HWY_NAMESPACE;
        const hn::RebindToSigned<D> di;
        constexpr int kLanes = int(hn::MaxLanes(D()));
        static_assert(kLanes == LinearPieces::kMax || 2 * kLanes == LinearPieces::kMax, "16 pieces: 1 or 2 vectors");
        // Lane j's entry of a column of kMax numbers (float or int32).
        const auto column = [&](auto tag, const auto* c, auto j) {
            const auto low = hn::IndicesFromVec(tag, hn::And(j, hn::Set(di, kLanes - 1)));
            const auto lo = hn::TableLookupLanes(hn::Load(tag, c), low);
            if constexpr (kLanes == LinearPieces::kMax) return lo;
            else return hn::IfThenElse(hn::RebindMask(tag, hn::Gt(j, hn::Set(di, kLanes - 1))),
                                       hn::TableLookupLanes(hn::Load(tag, c + kLanes), low), lo);
        };
        // value + slope · dx per channel, from the lanes' values and slopes.
        const auto evaluate = [&](auto value, auto slope, V dx) {
            const auto channel = [&](int c) { return hn::Add(value(c), hn::Mul(slope(c), dx)); };
            r = channel(0), g = channel(1), b = channel(2);
            const V s = channel(3);
            sigma = hn::IfThenElseZero(hn::And(active, hn::Gt(s, zero)), s);
        };
        if (pieces->count == 1)  // one line (grey): its numbers broadcast, no permutes
            return evaluate([&](int c) { return hn::Set(d, pieces->value[c][0]); },
                            [&](int c) { return hn::Set(d, pieces->slope[c][0]); }, x);
        auto j = column(di, pieces->firstOfBucket, hn::ShiftRight<LinearPieces::kBucketShift>(hn::ConvertTo(di, x)));
        for (int k = 0; k < pieces->knotsPerBucket; ++k)  // j += (x ≥ next knot): the mask as −1
            j = hn::Sub(j, hn::VecFromMask(di, hn::RebindMask(di, hn::Ge(x, column(d, pieces->next, j)))));
        const auto at = [&](const float* c) { return column(d, c, j); };
        evaluate([&](int c) { return at(pieces->value[c]); }, [&](int c) { return at(pieces->slope[c]); },
                 hn::Sub(x, at(pieces->knot)));
    }
};

/// Shading's factors (shading/shade_leaf.h) on the classified lanes of voxel n, as applyShading
/// does for one voxel: colour c·D + S, σ·G; a σ·G that is not > 0 (0, or NaN from a non-finite
/// neighbour's gradient) becomes 0, which the voxel-by-voxel paths skip. @p factors: nullptr:
/// unshaded, nothing changes.
template <class D>
HWY_INLINE void ApplyFactors(D d, const LeafFactors* factors, int n, hwy::HWY_NAMESPACE::Vec<D>& sigma,
                             hwy::HWY_NAMESPACE::Vec<D>& r, hwy::HWY_NAMESPACE::Vec<D>& g, hwy::HWY_NAMESPACE::Vec<D>& b) {
    namespace hn = hwy::HWY_NAMESPACE;
    if (!factors) return;
    const auto diffuse = hn::LoadU(d, factors->diffuse + n), specular = hn::LoadU(d, factors->specular + n);
    r = hn::Add(hn::Mul(r, diffuse), specular);
    g = hn::Add(hn::Mul(g, diffuse), specular);
    b = hn::Add(hn::Mul(b, diffuse), specular);
    sigma = hn::Mul(sigma, hn::LoadU(d, factors->opacity + n));
    sigma = hn::IfThenElseZero(hn::Gt(sigma, hn::Zero(d)), sigma);
}

/// A leaf's active lanes at voxel n (a vector of whole rows: n = x·64 + y·8): finite values,
/// and on in @p maskWords (nullptr: a dense leaf).
template <class D>
HWY_INLINE auto ActiveLanes(D d, hwy::HWY_NAMESPACE::Vec<D> value, const uint64_t* maskWords, int n) {
    namespace hn = hwy::HWY_NAMESPACE;
    auto active = hn::IsFinite(value);
    if (maskWords) {
        const uint64_t bits = maskWords[n >> 6] >> (n & 63);
        uint8_t bytes[8];
        std::memcpy(bytes, &bits, sizeof bytes);
        active = hn::And(active, hn::LoadMaskBits(d, bytes));
    }
    return active;
}
#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
