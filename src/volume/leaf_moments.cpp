// volume/leaf_moments.cpp — leafMoments with Google Highway (see leaf_moments.h). Compiled once
// per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volume/leaf_moments.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <cstring>

#include "volume/classify-inl.h"
#include "volume/leaf_moments.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kLeafSide = 8;

bool LeafMomentsSupported() { return WholeRowsSupported(hn::ScalableTag<float>()); }

#if HWY_TARGET != HWY_SCALAR
/// A vector of whole 8-voxel rows folded onto one row: lane z of the result is the sum of lane z of
/// every row (16 lanes: the two halves added; 8 lanes: as it is).
template <class D>
auto FoldRows(D d, hn::Vec<D> v) {
    if constexpr (hn::MaxLanes(D()) == 16) {
        const hn::Half<D> dh;
        return hn::Add(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v));
    } else {
        (void)d;
        return v;
    }
}
#endif

/// The sums for whole-row vectors (a template, so that targets without them, whose ops it uses
/// do not exist, never instantiate the body).
template <class D>
void RowMoments(D d, const float* values, const uint64_t* maskWords, const ClassificationTable& table, int level,
                CellMoments* out, const LeafFactors* factors) {
#if HWY_TARGET != HWY_SCALAR  // one lane: no halves or lane pairs to name (and kWholeRows is false)
    if constexpr (kWholeRows<D>) {
        const hn::RebindToSigned<decltype(d)> di;
        using V = hn::Vec<decltype(d)>;
        const int lanes = int(hn::Lanes(d)), rowsPerVector = lanes / kLeafSide;
        const int side = 1 << level, cells = kLeafSide >> level;
        const float half = 0.5f * float(side - 1);
        const ClassifyLanes<D> classify(d, table);
        const V zero = hn::Zero(d);
        // Per lane: its z (lane mod 8) and row within the vector (lane / 8).
        const auto lane = hn::Iota(di, 0);
        const auto laneZ = hn::And(lane, hn::Set(di, kLeafSide - 1));
        const V dz = hn::Sub(hn::ConvertTo(d, hn::And(laneZ, hn::Set(di, side - 1))), hn::Set(d, half));
        const V laneRow = hn::ConvertTo(d, hn::ShiftRight<3>(lane));
        for (int cx = 0; cx < cells; ++cx)
            for (int cy = 0; cy < cells; ++cy) {
                // Lane by lane (each lane one z): the sums over the cell's voxels in that lane. The
                // z offset is the lane's own, so the sums with a factor dz are the lane's sums times
                // dz, taken at the fold (Sz = S·dz, Szz = S·dz², Sxz = Sx·dz, Syz = Sy·dz); and dx is
                // one per plane x, so a plane's sums P, Py, Pyy take it once per plane (Sx += dx·P,
                // Sxx += dx²·P, Sxy += dx·Py): 11 operations a vector instead of 20, and 5 a plane.
                V S = zero, Sx = zero, Sy = zero, Sxx = zero, Syy = zero, Sxy = zero, Er = zero, Eg = zero, Eb = zero,
                  count = zero;
                for (int x = cx * side; x < (cx + 1) * side; ++x) {
                    V P = zero, Py = zero, Pyy = zero;
                    for (int y = cy * side; y < (cy + 1) * side; y += rowsPerVector) {
                        const int n = x * 64 + y * 8;
                        const V value = hn::LoadU(d, values + n);
                        const auto active = ActiveLanes(d, value, maskWords, n);
                        const V index = classify.Index(value, active);
                        // A vector of transparent voxels (σ = 0 exactly, so every sum takes +0 and
                        // no count): no gathers. Most of a CT's air and soft tissue under a bone
                        // transfer function.
                        if (classify.AllTransparent(index)) continue;
                        V sigma, red, green, blue;
                        classify(index, active, sigma, red, green, blue);
                        ApplyFactors(d, factors, n, sigma, red, green, blue);
                        count = hn::Add(count, hn::IfThenElseZero(hn::Gt(sigma, zero), hn::Set(d, 1.f)));
                        Er = hn::MulAdd(sigma, red, Er);
                        Eg = hn::MulAdd(sigma, green, Eg);
                        Eb = hn::MulAdd(sigma, blue, Eb);
                        const V dy = hn::Add(hn::Set(d, float(y & (side - 1)) - half), laneRow);
                        const V sy = hn::Mul(sigma, dy);
                        P = hn::Add(P, sigma), Py = hn::Add(Py, sy), Pyy = hn::MulAdd(sy, dy, Pyy);
                    }
                    const float ox = float(x & (side - 1)) - half;  // dx² = ox² exactly (ox a half-integer ≤ 3.5)
                    const V dx = hn::Set(d, ox);
                    S = hn::Add(S, P), Sx = hn::MulAdd(P, dx, Sx), Sxx = hn::MulAdd(P, hn::Set(d, ox * ox), Sxx);
                    Sy = hn::Add(Sy, Py), Syy = hn::Add(Syy, Pyy), Sxy = hn::MulAdd(Py, dx, Sxy);
                }
                const V Sz = hn::Mul(S, dz), Szz = hn::Mul(Sz, dz), Sxz = hn::Mul(Sx, dz), Syz = hn::Mul(Sy, dz);
                // Each cell along z is the lanes whose z lies in it: fold the rows a vector holds onto
                // one row of 8 lanes (z), then add the `side` neighbouring lanes of each cell, so that
                // cell cz's sum lands in lane cz·side (a few shuffles per sum, where a masked
                // reduction of the whole vector per cell took 56 per (cx, cy) at level 1).
                alignas(32) float z8[14][8];
                const auto fold = [&](V v, float* lanesOut) {
                    auto r = FoldRows(d, v);
                    const auto d8 = hn::DFromV<decltype(r)>();
                    if (side >= 2) r = hn::Add(r, hn::Shuffle2301(r));           // pairs
                    if (side >= 4) r = hn::Add(r, hn::Shuffle1032(r));           // fours
                    if (side >= 8) r = hn::Add(r, hn::ConcatLowerUpper(d8, r, r));  // the two halves
                    hn::Store(r, d8, lanesOut);
                };
                const V sums[14] = {S, Er, Eg, Eb, Sx, Sy, Sz, Sxx, Syy, Szz, Sxy, Sxz, Syz, count};
                for (int k = 0; k < 14; ++k) fold(sums[k], z8[k]);
                for (int cz = 0; cz < cells; ++cz) {
                    const int lz = cz * side;
                    CellMoments& m = out[(cx * cells + cy) * cells + cz];
                    m.m = z8[0][lz];
                    m.emission = glm::vec3(z8[1][lz], z8[2][lz], z8[3][lz]);
                    m.first = glm::vec3(z8[4][lz], z8[5][lz], z8[6][lz]);
                    m.xx = z8[7][lz], m.yy = z8[8][lz], m.zz = z8[9][lz];
                    m.xy = z8[10][lz], m.xz = z8[11][lz], m.yz = z8[12][lz];
                    m.n = uint32_t(z8[13][lz]);
                }
            }
    } else
#endif
    {
        (void)d, (void)values, (void)maskWords, (void)table, (void)level, (void)out, (void)factors;
    }
}

void LeafMomentsImpl(const float* values, const uint64_t* maskWords, const ClassificationTable& table, int level,
                     CellMoments* out, const LeafFactors* factors) {
    RowMoments(hn::ScalableTag<float>(), values, maskWords, table, level, out, factors);
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(LeafMomentsImpl);
HWY_EXPORT(LeafMomentsSupported);

bool leafMomentsSupported() { return HWY_DYNAMIC_DISPATCH(LeafMomentsSupported)(); }

void leafMoments(const float* values, const uint64_t* maskWords, const ClassificationTable& table, int level,
                 CellMoments* out, const LeafFactors* factors) {
    HWY_DYNAMIC_DISPATCH(LeafMomentsImpl)(values, maskWords, table, level, out, factors);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
