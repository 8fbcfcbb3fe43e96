// render/project_vector.cpp — projectSplatsVector with Google Highway (see project_vector.h).
// Compiled once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU
// has. Every expression below is the scalar one it mirrors, operation for operation (named in
// the comments), and the file is compiled without contraction (CMakeLists.txt), so a fused
// multiply-add never changes a rounding.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/project_vector.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>

#include "render/project_vector.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void ProjectSplats(SplatLanes& L, size_t n, const SplatLaneContext& ctx) {
    const hn::ScalableTag<double> d;
    using V = hn::Vec<decltype(d)>;
    const size_t N = hn::Lanes(d);
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
    const V f = hn::Set(d, ctx.focal), px = hn::Set(d, ctx.principalX), py = hn::Set(d, ctx.principalY);
    const V r = hn::Set(d, ctx.radius), r2 = hn::Set(d, ctx.radius * ctx.radius), fr = hn::Set(d, ctx.focal * ctx.radius);
    const V widen = hn::Set(d, ctx.widen), hf = hn::Set(d, ctx.spacingTimesFocal), threshold = hn::Set(d, ctx.threshold);
    const V minDen = hn::Set(d, 1e-12), exactBound = hn::Set(d, ctx.exactIndexError);
    const V width = hn::Set(d, double(ctx.width)), height = hn::Set(d, double(ctx.height));
    const V invR2 = hn::Set(d, 1.0 / (ctx.radius * ctx.radius)), invF = hn::Set(d, 1.0 / ctx.focal);
    for (size_t i = 0; i < n; i += N) {
        const V x = hn::Load(d, L.x + i), y = hn::Load(d, L.y + i), z = hn::Load(d, L.z + i);
        // projectVoxel: in hybrid a point where h·f/z < threshold (z > 0 here).
        auto handled = hn::And(hn::And(hn::IsFinite(x), hn::IsFinite(y)), hn::And(hn::IsFinite(z), hn::Gt(z, zero)));
        if (ctx.pointsBelow) handled = hn::And(handled, hn::Not(hn::Lt(hn::Div(hf, z), threshold)));
        if (hn::AllFalse(d, handled)) {  // all points (far views) or the scalar path's: nothing to do
            for (size_t k = 0; k < N && i + k < n; ++k) L.status[i + k] = SplatLanes::kScalar;
            continue;
        }
        // projectSphere: D = |c| (glm: (x² + y²) + z²), ρ = √(x² + y²), sin α = r/D; an Ellipse
        // where D > r, not z ≤ r, and den = (z² − r²)/D² not below kMinDen.
        const V xx = hn::Mul(x, x), yy = hn::Mul(y, y), zz = hn::Mul(z, z);
        const V D = hn::Sqrt(hn::Add(hn::Add(xx, yy), zz));
        const V rho = hn::Sqrt(hn::Add(xx, yy));
        const V q = hn::Sub(zz, r2);  // z² − r² (fillEllipse's q, den's numerator)
        const V den = hn::Div(q, hn::Mul(D, D));
        handled = hn::And(handled, hn::And(hn::Gt(D, r), hn::And(hn::Gt(z, r), hn::Not(hn::Lt(den, minDen)))));
        const V sinAlpha = hn::Div(r, D);
        // fillEllipse: u = (x, −y)·(1/ρ) ((1, 0) on the axis); centre = principal + u·(f·ρ·z·(1/q));
        // a = f·r·√(D² − r²)·(1/q), b = f·r/√q.
        const auto onAxis = hn::Not(hn::Gt(rho, zero));
        const V invRho = hn::Div(one, rho), invQ = hn::Div(one, q);
        const V ux = hn::IfThenElse(onAxis, one, hn::Mul(x, invRho));
        const V uy = hn::IfThenElse(onAxis, zero, hn::Mul(hn::Neg(y), invRho));
        const V s = hn::Mul(hn::Mul(hn::Mul(f, rho), z), invQ);
        const V cx = hn::Add(px, hn::Mul(ux, s)), cy = hn::Add(py, hn::Mul(uy, s));
        const V a = hn::Mul(hn::Mul(fr, hn::Sqrt(hn::Sub(hn::Mul(D, D), r2))), invQ);
        const V b = hn::Div(fr, hn::Sqrt(q));
        // makeScreenKernel: a' = √(a² + w), b' = √(b² + w); conic = inFrame(u, (1/a')², (1/b')²),
        // pullback = inFrame(u, a·(1/a'), b·(1/b')) with inFrame(u, X, Y) = X·u uᵀ + Y·v vᵀ, v = (−u.y, u.x).
        const V aw = hn::Sqrt(hn::Add(hn::Mul(a, a), widen)), bw = hn::Sqrt(hn::Add(hn::Mul(b, b), widen));
        const V uxux = hn::Mul(ux, ux), uyuy = hn::Mul(uy, uy), uyux = hn::Mul(uy, ux);
        const V vx = hn::Neg(uy), vy = ux;
        const V vxvx = hn::Mul(vx, vx), vyvx = hn::Mul(vy, vx), vyvy = hn::Mul(vy, vy);
        const V invAw = hn::Div(one, aw), invBw = hn::Div(one, bw);
        const V X = hn::Mul(invAw, invAw), Y = hn::Mul(invBw, invBw);
        const V qxx = hn::Add(hn::Mul(X, uxux), hn::Mul(Y, vxvx));
        const V qxy = hn::Add(hn::Mul(X, uyux), hn::Mul(Y, vyvx));
        const V qyy = hn::Add(hn::Mul(X, uyuy), hn::Mul(Y, vyvy));
        const V ra = hn::Mul(a, invAw), rb = hn::Mul(b, invBw);
        const V amplitude = hn::Mul(ra, rb);
        const V p00 = hn::Add(hn::Mul(ra, uxux), hn::Mul(rb, vxvx));
        const V p01 = hn::Add(hn::Mul(ra, uyux), hn::Mul(rb, vyvx));  // = p10
        const V p11 = hn::Add(hn::Mul(ra, uyuy), hn::Mul(rb, vyvy));
        // Bounds: half = (√(a'²u.x² + b'²v.x²), √(a'²u.y² + b'²v.y²)) (glm: ((a'·a')·u)·u).
        const V aa = hn::Mul(aw, aw), bb = hn::Mul(bw, bw);
        const V hx = hn::Sqrt(hn::Add(hn::Mul(hn::Mul(aa, ux), ux), hn::Mul(hn::Mul(bb, vx), vx)));
        const V hy = hn::Sqrt(hn::Add(hn::Mul(hn::Mul(aa, uy), uy), hn::Mul(hn::Mul(bb, vy), vy)));
        // pixelRange(bounds, W, H): first = ⌈clamp(lo − ½, 0, n)⌉, last = ⌊clamp(hi − ½, −1, n − 1)⌋
        // (as a truncation and a compare).
        const auto first = [&](V lo, V size) {
            const V t = hn::Min(hn::Max(hn::Sub(lo, half), zero), size);
            const V i = hn::Trunc(t);
            return hn::IfThenElse(hn::Lt(i, t), hn::Add(i, one), i);
        };
        const auto last = [&](V hi, V size) {
            const V t = hn::Min(hn::Max(hn::Sub(hi, half), hn::Neg(one)), hn::Sub(size, one));
            const V i = hn::Trunc(t);
            return hn::IfThenElse(hn::Gt(i, t), hn::Sub(i, one), i);
        };
        const V x0 = first(hn::Sub(cx, hx), width), y0 = first(hn::Sub(cy, hy), height);
        const V x1 = last(hn::Add(cx, hx), width), y1 = last(hn::Add(cy, hy), height);
        const auto onImage = hn::And(hn::Ge(x1, x0), hn::Ge(y1, y0));  // else makeSplat culls it (no pixel)
        // affineIndexError: (ρ·r)/(z·√((D − r)(D + r))).
        const V error = hn::Div(hn::Mul(rho, r), hn::Mul(z, hn::Sqrt(hn::Mul(hn::Sub(D, r), hn::Add(D, r)))));
        const auto exact = hn::And(hn::Gt(error, exactBound), hn::FirstN(d, ctx.autoExactIndex ? N : 0));
        hn::Store(amplitude, d, L.amplitude + i);
        hn::Store(cx, d, L.centreX + i), hn::Store(cy, d, L.centreY + i);
        hn::Store(qxx, d, L.conicXX + i), hn::Store(qxy, d, L.conicXY + i), hn::Store(qyy, d, L.conicYY + i);
        hn::Store(sinAlpha, d, L.sinAlpha + i);
        hn::Store(x0, d, L.x0 + i), hn::Store(y0, d, L.y0 + i), hn::Store(x1, d, L.x1 + i), hn::Store(y1, d, L.y1 + i);
        // The lanes' status: 0 scalar; else kSplat or kExactIndex, plus kOffImage.
        const V kind = hn::IfThenElse(exact, hn::Set(d, double(SplatLanes::kExactIndex)), hn::Set(d, double(SplatLanes::kSplat)));
        const V status = hn::IfThenElseZero(handled, hn::IfThenElse(onImage, kind, hn::Add(kind, hn::Set(d, double(SplatLanes::kOffImage)))));
        alignas(64) double st[HWY_MAX_BYTES / sizeof(double)];
        hn::Store(status, d, st);
        for (size_t k = 0; k < N && i + k < n; ++k) L.status[i + k] = uint8_t(st[k]);
        if (hn::AllFalse(d, hn::And(handled, exact))) continue;
        // makeExactIndexMap from the kernel's centre (makeSplat): p' = centre, v0 = ((cx − px)·(1/f),
        // −(cy − py)·(1/f), 1), vx = (P00·(1/f), −P01·(1/f), 0), vy = (P10·(1/f), −P11·(1/f), 0);
        // A = c × v0, B = c × vx, C = c × vy (glm::cross).
        const V pxp = cx, pyp = cy;
        const V v0x = hn::Mul(hn::Sub(pxp, px), invF), v0y = hn::Mul(hn::Neg(hn::Sub(pyp, py)), invF), v0z = one;
        const V vxx = hn::Mul(p00, invF), vxy = hn::Mul(hn::Neg(p01), invF), vxz = zero;
        const V vyx = hn::Mul(p01, invF), vyy = hn::Mul(hn::Neg(p11), invF), vyz = zero;
        const auto cross = [&](V wx, V wy, V wz, V out[3]) {
            out[0] = hn::Sub(hn::Mul(y, wz), hn::Mul(wy, z));
            out[1] = hn::Sub(hn::Mul(z, wx), hn::Mul(wz, x));
            out[2] = hn::Sub(hn::Mul(x, wy), hn::Mul(wx, y));
        };
        V A[3], B[3], C[3];
        cross(v0x, v0y, v0z, A), cross(vxx, vxy, vxz, B), cross(vyx, vyy, vyz, C);
        const V all[19] = {v0x, v0y, v0z, vxx, vxy, vxz, vyx, vyy, vyz, A[0], A[1], A[2],
                           B[0], B[1], B[2], C[0], C[1], C[2], invR2};
        for (int k = 0; k < 19; ++k) hn::Store(all[k], d, L.map[k] + i);
    }
}

void SlabsOf(const float* distance, size_t n, double slabLength, int64_t first, int64_t last, int64_t* slab) {
    const hn::ScalableTag<double> d;
    const hn::Rebind<float, decltype(d)> df;
    const hn::RebindToSigned<decltype(d)> di;
    const size_t N = hn::Lanes(d);
    const auto length = hn::Set(d, slabLength);
    const auto lo = hn::Set(di, first), hi = hn::Set(di, last);
    const auto slabsAt = [&](auto floats) {  // ⌊d / L⌋ clamped: Floor is exact, the integer fits
        const auto q = hn::Floor(hn::Div(hn::PromoteTo(d, floats), length));
        return hn::Min(hn::Max(hn::ConvertTo(di, q), lo), hi);
    };
    size_t i = 0;
    for (; i + N <= n; i += N) hn::StoreU(slabsAt(hn::LoadU(df, distance + i)), di, slab + i);
    if (i < n) {  // the last n − i through buffers of a whole vector (no access past either array)
        HWY_ALIGN float in[64] = {};
        HWY_ALIGN int64_t out[64];
        static_assert(hn::MaxLanes(d) <= 64);
        std::copy(distance + i, distance + n, in);
        hn::Store(slabsAt(hn::Load(df, in)), di, out);
        std::copy(out, out + (n - i), slab + i);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(ProjectSplats);
HWY_EXPORT(SlabsOf);

void slabsOf(const float* distance, size_t n, double slabLength, int64_t first, int64_t last, int64_t* slab) {
    HWY_DYNAMIC_DISPATCH(SlabsOf)(distance, n, slabLength, first, last, slab);
}

void projectSplatsVector(SplatLanes& lanes, size_t n, const SplatLaneContext& ctx) {
    HWY_DYNAMIC_DISPATCH(ProjectSplats)(lanes, n, ctx);
}

void SplatLanes::exactMapInto(size_t i, ExactIndexMap& m) const {
    const auto v3 = [&](int k) { return glm::vec3(float(map[k][i]), float(map[k + 1][i]), float(map[k + 2][i])); };
    m.v0 = v3(0), m.vx = v3(3), m.vy = v3(6);
    m.A = v3(9), m.B = v3(12), m.C = v3(15);
    m.invR2 = float(map[18][i]);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
