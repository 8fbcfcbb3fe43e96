// composite/splat_raster.cpp — the splat loop over one tile with Google Highway (see splat_raster.h).
// Compiled once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the
// CPU supports at run time.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite/splat_raster.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <algorithm>
#include <cmath>

#include "composite/opacity.h"
#include "composite/splat_raster.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int kStride = 16;  // tile row stride (kTileSize)

/// The row's chord of the support ellipse i² < 1 (one pixel of slack each side; the mask decides).
inline bool rowChord(const SplatRaster& s, float dy, int& xa, int& xb) {
    const float b = s.qxy * dy, disc = b * b - s.qxx * (s.qyy * dy * dy - 1.f);
    if (!(disc > 0.f)) return false;
    const float root = std::sqrt(disc);
    const float lo = s.cx - 0.5f + (-b - root) / s.qxx, hi = s.cx - 0.5f + (-b + root) / s.qxx;
    xa = std::max(s.x0, int(std::floor(lo)));
    xb = std::min(s.x1, int(std::ceil(hi)));
    return xa <= xb;
}

void DrawSplatRows(const SplatRaster& s, const TileBuffers& tile) {
    const hn::CappedTag<float, kStride> d;
    const int n = int(hn::Lanes(d));
    using V = hn::Vec<decltype(d)>;
    const V lane = hn::Iota(d, 0.5f);  // pixel centre offsets 0.5, 1.5, …
    const V zero = hn::Zero(d), one = hn::Set(d, 1.f), two = hn::Set(d, 2.f);
    const V qxx = hn::Set(d, s.qxx), qxy2 = hn::Set(d, 2.f * s.qxy), qyy = hn::Set(d, s.qyy);
    const V scale = hn::Set(d, s.scale), eps = hn::Set(d, s.epsilon);
    const V cr = hn::Set(d, s.color.x), cg = hn::Set(d, s.color.y), cb = hn::Set(d, s.color.z);
    for (int y = s.y0; y <= s.y1; ++y) {
        const float dyf = float(y) + 0.5f - s.cy;
        int xa, xb;
        if (!rowChord(s, dyf, xa, xb)) continue;
        const V dy = hn::Set(d, dyf);
        const V i2Row = hn::Mul(hn::Mul(qyy, dy), dy);  // Qyy dy²
        const V lo = hn::Set(d, float(xa)), hi = hn::Set(d, float(xb) + 0.75f);
        // Exact index: the ray terms that depend on the row only (ExactIndexMap::d2).
        const glm::vec3 wRow = s.map.A + dyf * s.map.C, vRow = s.map.v0 + dyf * s.map.vy;
        const int row = (y - tile.y0) * kStride;
        for (int c = (xa - tile.x0) / n * n; c <= xb - tile.x0; c += n) {
            const V xPix = hn::Add(hn::Set(d, float(tile.x0 + c)), lane);  // pixel centres
            const V dx = hn::Sub(xPix, hn::Set(d, s.cx));
            // i² = Qxx dx² + 2 Qxy dx dy + Qyy dy²
            const V i2 = hn::MulAdd(hn::Mul(qxx, dx), dx, hn::MulAdd(hn::Mul(qxy2, dx), dy, i2Row));
            float* pt = tile.T + row + c;
            const V T = hn::Load(d, pt);
            auto mask = hn::And(hn::And(hn::Ge(xPix, lo), hn::Lt(xPix, hi)), hn::And(hn::Lt(i2, one), hn::Ge(T, eps)));
            if (hn::AllFalse(d, mask)) continue;
            V t;
            if (s.exactIndex) {  // d² = |w|² / |v|² / r², w = c × v (DESIGN §3)
                const V wx = hn::MulAdd(dx, hn::Set(d, s.map.B.x), hn::Set(d, wRow.x));
                const V wy = hn::MulAdd(dx, hn::Set(d, s.map.B.y), hn::Set(d, wRow.y));
                const V wz = hn::MulAdd(dx, hn::Set(d, s.map.B.z), hn::Set(d, wRow.z));
                const V vx = hn::MulAdd(dx, hn::Set(d, s.map.vx.x), hn::Set(d, vRow.x));
                const V vy = hn::MulAdd(dx, hn::Set(d, s.map.vx.y), hn::Set(d, vRow.y));
                const V vz = hn::MulAdd(dx, hn::Set(d, s.map.vx.z), hn::Set(d, vRow.z));
                const V w2 = hn::MulAdd(wx, wx, hn::MulAdd(wy, wy, hn::Mul(wz, wz)));
                const V v2 = hn::MulAdd(vx, vx, hn::MulAdd(vy, vy, hn::Mul(vz, vz)));
                t = hn::Mul(hn::Div(w2, v2), hn::Set(d, s.map.invR2));
                mask = hn::And(mask, hn::Lt(t, one));
            } else {
                t = i2;
            }
            t = hn::Min(hn::Max(t, zero), one);
            // τ = scale·√(1 − t)·G(2t − 1), Horner (footprint_poly.h)
            const V x = hn::MulSub(two, t, one);
            V p = hn::Set(d, s.coef[FootprintPolynomials::kDegree]);
#pragma GCC unroll 16
            for (int j = FootprintPolynomials::kDegree - 1; j >= 0; --j) p = hn::MulAdd(p, x, hn::Set(d, s.coef[size_t(j)]));
            const V tau = hn::Max(hn::Mul(hn::Mul(scale, hn::Sqrt(hn::Sub(one, t))), p), zero);
            const V alpha = hn::Neg(hn::Expm1(d, hn::Neg(tau)));  // 1 − e^{−τ}
            const V ta = hn::Mul(T, alpha);
            float *pr = tile.R + row + c, *pg = tile.G + row + c, *pb = tile.B + row + c;
            hn::Store(hn::IfThenElse(mask, hn::MulAdd(ta, cr, hn::Load(d, pr)), hn::Load(d, pr)), d, pr);
            hn::Store(hn::IfThenElse(mask, hn::MulAdd(ta, cg, hn::Load(d, pg)), hn::Load(d, pg)), d, pg);
            hn::Store(hn::IfThenElse(mask, hn::MulAdd(ta, cb, hn::Load(d, pb)), hn::Load(d, pb)), d, pb);
            hn::Store(hn::IfThenElse(mask, hn::Sub(T, ta), T), d, pt);  // T·(1 − α)
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(DrawSplatRows);

void drawSplatVector(const SplatRaster& s, const TileBuffers& tile) { HWY_DYNAMIC_DISPATCH(DrawSplatRows)(s, tile); }

void drawSplatScalarPoly(const SplatRaster& s, const TileBuffers& tile) {
    constexpr int kStride = 16;
    for (int y = s.y0; y <= s.y1; ++y) {
        const float dy = float(y) + 0.5f - s.cy;
        for (int x = s.x0; x <= s.x1; ++x) {
            const int i = (y - tile.y0) * kStride + (x - tile.x0);
            if (!(tile.T[i] >= s.epsilon)) continue;
            const float dx = float(x) + 0.5f - s.cx;
            const float i2 = s.qxx * dx * dx + 2.f * s.qxy * dx * dy + s.qyy * dy * dy;
            if (!(i2 < 1.f)) continue;
            const float t = s.exactIndex ? s.map.d2(dx, dy) : i2;
            const float tau = s.scale * FootprintPolynomials::evaluate(s.coef, t);
            const float alpha = opacityFromOpticalDepth(tau);
            const float ta = tile.T[i] * alpha;
            tile.R[i] += ta * s.color.x;
            tile.G[i] += ta * s.color.y;
            tile.B[i] += ta * s.color.z;
            tile.T[i] -= ta;
        }
    }
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
