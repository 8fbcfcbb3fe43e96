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

#include "pointfilter/point_weight-inl.h"

#include "pointfilter/point_filter.h"
#include "render/project_vector.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// pixelRange's rounding of a bound, vectors at a time: the first pixel of a low bound,
/// ⌈clamp(lo − ½, 0, n)⌉, and the last of a high bound, ⌊clamp(hi − ½, −1, n − 1)⌋ (each a
/// truncation and a compare, as the scalar clamps, casts and compares); @p size is n.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V FirstPixel(D d, V lo, V size) {
    const V t = hn::Min(hn::Max(hn::Sub(lo, hn::Set(d, 0.5)), hn::Zero(d)), size);
    const V i = hn::Trunc(t);
    return hn::IfThenElse(hn::Lt(i, t), hn::Add(i, hn::Set(d, 1.0)), i);
}
template <class D, class V = hn::Vec<D>>
HWY_INLINE V LastPixel(D d, V hi, V size) {
    const V one = hn::Set(d, 1.0);
    const V t = hn::Min(hn::Max(hn::Sub(hi, hn::Set(d, 0.5)), hn::Neg(one)), hn::Sub(size, one));
    const V i = hn::Trunc(t);
    return hn::IfThenElse(hn::Gt(i, t), hn::Sub(i, one), i);
}

/// PrefilterRamp::at, vectors at a time (the same double operations): the low-pass V at spacing
/// @p s, minified − span·(s − kStart)·kInvWidth on the ramp.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V LowPassAt(D d, const PrefilterRamp& ramp, V s) {
    const V minified = hn::Set(d, ramp.minified), span = hn::Set(d, ramp.span);
    const V t = hn::Mul(hn::Sub(s, hn::Set(d, PrefilterRamp::kStart)), hn::Set(d, PrefilterRamp::kInvWidth));
    const V inside = hn::IfThenElse(hn::Lt(t, hn::Set(d, 1.0)), hn::Sub(minified, hn::Mul(span, t)), hn::Sub(minified, span));
    return hn::IfThenElse(hn::Gt(t, hn::Zero(d)), inside, minified);
}

void ProjectSplats(SplatLanes& L, size_t n, const SplatLaneContext& ctx) {
    const hn::ScalableTag<double> d;
    using V = hn::Vec<decltype(d)>;
    const size_t N = hn::Lanes(d);
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
    const V f = hn::Set(d, ctx.focal), px = hn::Set(d, ctx.principalX), py = hn::Set(d, ctx.principalY);
    const V r = hn::Set(d, ctx.radius), r2 = hn::Set(d, ctx.radius * ctx.radius), fr = hn::Set(d, ctx.focal * ctx.radius);
    const V widenPerVariance = hn::Set(d, ctx.widenPerVariance), hf = hn::Set(d, ctx.spacingTimesFocal);
    const V threshold = hn::Set(d, ctx.threshold);
    const V minDen = hn::Set(d, 1e-12), exactBound = hn::Set(d, ctx.exactIndexError);
    const V width = hn::Set(d, double(ctx.width)), height = hn::Set(d, double(ctx.height));
    const V invR2 = hn::Set(d, 1.0 / (ctx.radius * ctx.radius)), invF = hn::Set(d, 1.0 / ctx.focal);
    for (size_t i = 0; i < n; i += N) {
        const V x = hn::Load(d, L.x + i), y = hn::Load(d, L.y + i), z = hn::Load(d, L.z + i);
        // projectVoxel: in hybrid a point where h·f/z < threshold (z > 0 here).
        auto handled = hn::And(hn::And(hn::IsFinite(x), hn::IsFinite(y)), hn::And(hn::IsFinite(z), hn::Gt(z, zero)));
        const V spacing = hn::Div(hf, z);  // projectVoxel's h·f/z
        if (ctx.pointsBelow) handled = hn::And(handled, hn::Not(hn::Lt(spacing, threshold)));
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
        // supportWidening(kernel, V) with V = lowPass.at(h·f/z) (splatKernelFor).
        const V widen = hn::Mul(widenPerVariance, hn::Max(LowPassAt(d, ctx.lowPass, spacing), zero));
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
        // pixelRange(bounds, W, H).
        const V x0 = FirstPixel(d, hn::Sub(cx, hx), width), y0 = FirstPixel(d, hn::Sub(cy, hy), height);
        const V x1 = LastPixel(d, hn::Add(cx, hx), width), y1 = LastPixel(d, hn::Add(cy, hy), height);
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
        // v_c = v0, A = c × v0 (glm::cross), κ = v0·v0 − (A·A)·(1/r²); then exactIndexMapOf: each
        // coefficient a dot product (glm: (x·x' + y·y') + z·z', the z parts 1 or 0) times 1/κ.
        const V v0x = hn::Mul(hn::Sub(cx, px), invF), v0y = hn::Mul(hn::Neg(hn::Sub(cy, py)), invF);
        const V vxx = hn::Mul(p00, invF), vxy = hn::Mul(hn::Neg(p01), invF);
        const V vyx = hn::Mul(p01, invF), vyy = hn::Mul(hn::Neg(p11), invF);
        const V Ax = hn::Sub(y, hn::Mul(v0y, z));  // glm::cross(c, v0) with v0.z = 1 (y·1 = y exactly)
        const V Ay = hn::Sub(hn::Mul(z, v0x), x);
        const V Az = hn::Sub(hn::Mul(x, v0y), hn::Mul(v0x, y));
        const auto dot2 = [](V ax, V ay, V bx, V by) { return hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)); };
        const V v0v0 = hn::Add(dot2(v0x, v0y, v0x, v0y), one);
        const V AA = hn::Add(dot2(Ax, Ay, Ax, Ay), hn::Mul(Az, Az));
        const V inv = hn::Div(one, hn::Sub(v0v0, hn::Mul(AA, invR2)));
        const V two = hn::Set(d, 2.0);
        const V all[6] = {hn::Mul(v0v0, inv),
                          hn::Mul(hn::Mul(two, dot2(v0x, v0y, vxx, vxy)), inv),
                          hn::Mul(hn::Mul(two, dot2(v0x, v0y, vyx, vyy)), inv),
                          hn::Mul(dot2(vxx, vxy, vxx, vxy), inv),
                          hn::Mul(hn::Mul(two, dot2(vxx, vxy, vyx, vyy)), inv),
                          hn::Mul(dot2(vyx, vyy, vyx, vyy), inv)};
        for (int k = 0; k < 6; ++k) hn::Store(all[k], d, L.map[k] + i);
    }
}

/// makePoint's point (centre, V_point, total, whether it is culled) and pointSetupBox's box, in double lanes;
/// the float values the record keeps are stored in @p P. Lanes [0, m) are computed (m a whole
/// number of float vectors; the caller zeroes the inputs past n).
void PointBoxes(const SplatLanes& L, PointLanes& P, size_t m, const PointLaneContext& ctx) {
    const hn::CappedTag<double, 8> d;  // at most 8 lanes: a whole number of them in m on every target
    const hn::Rebind<float, decltype(d)> df;
    const hn::Rebind<int32_t, decltype(d)> di;
    using V = hn::Vec<decltype(d)>;
    const size_t N = hn::Lanes(d);
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
    const V f = hn::Set(d, ctx.focal), px = hn::Set(d, ctx.principalX), py = hn::Set(d, ctx.principalY);
    const V hf = hn::Set(d, ctx.spacingTimesFocal), threshold = hn::Set(d, ctx.threshold);
    const V h = hn::Set(d, ctx.voxelSize), M = hn::Set(d, ctx.voxelSize * ctx.voxelSize * ctx.voxelSize);
    const V sg = hn::Set(d, ctx.kernelSigma);
    const V maxRadius = hn::Set(d, kPointMaxRadiusPx), sigmas = hn::Set(d, kPointSupportSigmas);
    const V maxSide = hn::Set(d, double(kPointMaxSide));
    const V width = hn::Set(d, double(ctx.width)), height = hn::Set(d, double(ctx.height));
    for (size_t i = 0; i < m; i += N) {
        const V x = hn::Load(d, L.x + i), y = hn::Load(d, L.y + i), z = hn::Load(d, L.z + i);
        // projectVoxel: a point where z > 0 and h·f/z < threshold (the splat lanes' complement).
        const V spacing = hn::Div(hf, z);
        const auto point = hn::And(hn::And(hn::And(hn::IsFinite(x), hn::IsFinite(y)), hn::And(hn::IsFinite(z), hn::Gt(z, zero))),
                                   hn::Lt(spacing, threshold));
        if (hn::AllFalse(d, point)) {  // all splats (framed and close views) or the scalar path's
            for (size_t k = 0; k < N && i + k < m; ++k) P.status[i + k] = PointLanes::kScalar;
            // An empty sum of defined values for PointSums, which runs over whole vectors.
            const auto zeroF = hn::Zero(df);
            hn::Store(zeroF, df, P.centreX + i), hn::Store(zeroF, df, P.centreY + i);
            hn::Store(zeroF, df, P.invVariance + i), hn::Store(zeroF, df, P.radius2 + i);
            hn::Store(hn::Zero(di), di, P.x0 + i), hn::Store(hn::Zero(di), di, P.y0 + i);
            hn::Store(hn::Zero(di), di, P.nx + i), hn::Store(hn::Zero(di), di, P.ny + i);
            continue;
        }
        // Camera::project: (px + f·x/z, py − f·y/z).
        const V cx = hn::Add(px, hn::Div(hn::Mul(f, x), z)), cy = hn::Sub(py, hn::Div(hn::Mul(f, y), z));
        // pointFilterVariance(h·f/z) + spread: (V_h + (s_g·spacing)²) + spread, rounded to float.
        const V s = hn::Mul(sg, spacing);
        const V prefilter = LowPassAt(d, ctx.lowPass, spacing);  // projectVoxel's lowPass.at(h·f/z)
        const auto varianceF = hn::DemoteTo(df, hn::Add(hn::Add(prefilter, hn::Mul(s, s)), hn::PromoteTo(d, hn::Load(df, P.spread + i))));
        // pointDepositTotal(σ/h, h, f, c): σ_w·M·(f/z)·(f/z)·(|c|/z), |c| = √((x² + y²) + z²).
        const V fz = hn::Div(f, z);
        const V length = hn::Sqrt(hn::Add(hn::Add(hn::Mul(x, x), hn::Mul(y, y)), hn::Mul(z, z)));
        const V sigmaW = hn::Div(hn::PromoteTo(d, hn::Load(df, P.sigma + i)), h);
        const auto totalF = hn::DemoteTo(df, hn::Mul(hn::Mul(hn::Mul(hn::Mul(sigmaW, M), fz), fz), hn::Div(length, z)));
        // pixelRange of the box centre ± kPointMaxRadiusPx: not empty.
        const auto onImage = hn::And(hn::Ge(LastPixel(d, hn::Add(cx, maxRadius), width), FirstPixel(d, hn::Sub(cx, maxRadius), width)),
                                     hn::Ge(LastPixel(d, hn::Add(cy, maxRadius), height), FirstPixel(d, hn::Sub(cy, maxRadius), height)));
        const auto kept = hn::And(hn::And(hn::IsFinite(cx), hn::IsFinite(cy)),
                                  hn::And(onImage, hn::Gt(hn::PromoteTo(d, totalF), zero)));
        // setUpPointFilter from the float centre and variance: pointSetupBox's rs, box, 1/V, r_s².
        const auto cxF = hn::DemoteTo(df, cx), cyF = hn::DemoteTo(df, cy);
        const V cxs = hn::PromoteTo(d, cxF), cys = hn::PromoteTo(d, cyF), variance = hn::PromoteTo(d, varianceF);
        const auto boxable = hn::And(hn::Gt(variance, zero), hn::IsFinite(variance));  // else the scalar path
        const V rs = hn::Min(hn::Mul(sigmas, hn::Sqrt(variance)), maxRadius);
        const auto box = [&](V c, V& origin, V& count) {
            const V lo = hn::Sub(c, half);
            origin = hn::Add(hn::Floor(hn::Sub(lo, rs)), one);
            count = hn::Min(hn::Max(hn::Sub(hn::Ceil(hn::Add(lo, rs)), origin), zero), maxSide);
        };
        V x0, nx, y0, ny;
        box(cxs, x0, nx), box(cys, y0, ny);
        hn::Store(cxF, df, P.centreX + i), hn::Store(cyF, df, P.centreY + i);
        hn::Store(varianceF, df, P.variance + i), hn::Store(totalF, df, P.total + i);
        hn::Store(hn::DemoteTo(df, hn::Div(one, variance)), df, P.invVariance + i);
        hn::Store(hn::DemoteTo(df, hn::Mul(rs, rs)), df, P.radius2 + i);
        // Lanes not kept or not boxable hold any integers here: a small box keeps the sums' loop in range.
        const auto valid = hn::And(kept, boxable);
        hn::Store(hn::DemoteTo(di, hn::IfThenElseZero(valid, x0)), di, P.x0 + i);
        hn::Store(hn::DemoteTo(di, hn::IfThenElseZero(valid, y0)), di, P.y0 + i);
        hn::Store(hn::DemoteTo(di, hn::IfThenElseZero(valid, nx)), di, P.nx + i);
        hn::Store(hn::DemoteTo(di, hn::IfThenElseZero(valid, ny)), di, P.ny + i);
        // Status: a point (its filter's sum decides below), or the scalar path's, which also
        // culls (rare: the stream culls blocks off the image or transparent; the scalar path
        // writes the culled record's fields as projectVoxel has them).
        const V status = hn::IfThenElseZero(hn::And(point, valid), hn::Set(d, double(PointLanes::kPoint)));
        alignas(64) double st[HWY_MAX_BYTES / sizeof(double)];
        hn::Store(status, d, st);
        for (size_t k = 0; k < N && i + k < m; ++k) P.status[i + k] = uint8_t(st[k]);
    }
}

/// setupPoint's sum for a vector of points at once, each lane one point: the weights of its
/// kPointMaxSide columns and rows (PointWeight), each column summed down its rows in order (a
/// pixel outside the circle, a row past ny or a column past nx adding +0), then the columns
/// pairwise (sumColumnsPairwise). Stores 1/sum as the norm, and the sum.
void PointSums(PointLanes& P, size_t m, float* sums) {
    const hn::CappedTag<float, 16> d;  // at most 16 lanes: a whole number of them in m
    const hn::RebindToSigned<decltype(d)> di;
    using V = hn::Vec<decltype(d)>;
    const size_t N = hn::Lanes(d);
    const V half = hn::Set(d, 0.5f), zero = hn::Zero(d);
    for (size_t i = 0; i < m; i += N) {
        const V cx = hn::Load(d, P.centreX + i), cy = hn::Load(d, P.centreY + i);
        const V invV = hn::Load(d, P.invVariance + i), rs2 = hn::Load(d, P.radius2 + i);
        const auto x0 = hn::Load(di, P.x0 + i), y0 = hn::Load(di, P.y0 + i);
        const auto nx = hn::Load(di, P.nx + i), ny = hn::Load(di, P.ny + i);
        // A column past nx or a row past ny gets the squared offset +∞ (after its weight), so that
        // the circle's test dx² + dy² < r_s² alone leaves it out: one mask per term.
        const V outside = hn::Inf(d);
        V dx2[kPointMaxSide], gx[kPointMaxSide], dy2[kPointMaxSide], gy[kPointMaxSide];
        for (int k = 0; k < kPointMaxSide; ++k) {
            // (i + ½) − c in float: one rounding of the exact difference (PointSetup::offset).
            const V ox = hn::Sub(hn::Add(hn::ConvertTo(d, hn::Add(x0, hn::Set(di, k))), half), cx);
            const V oy = hn::Sub(hn::Add(hn::ConvertTo(d, hn::Add(y0, hn::Set(di, k))), half), cy);
            dx2[k] = hn::Mul(ox, ox), dy2[k] = hn::Mul(oy, oy);
            gx[k] = PointWeight(d, hn::Mul(dx2[k], invV));
            gy[k] = PointWeight(d, hn::Mul(dy2[k], invV));
            dx2[k] = hn::IfThenElse(hn::RebindMask(d, hn::Lt(hn::Set(di, k), nx)), dx2[k], outside);
            dy2[k] = hn::IfThenElse(hn::RebindMask(d, hn::Lt(hn::Set(di, k), ny)), dy2[k], outside);
        }
        V columns[kPointSumColumns];
        for (int ix = 0; ix < kPointSumColumns; ++ix) {
            columns[ix] = zero;
            if (ix >= kPointMaxSide) continue;
            for (int iy = 0; iy < kPointMaxSide; ++iy) {
                const auto in = hn::Lt(hn::Add(dx2[ix], dy2[iy]), rs2);
                columns[ix] = hn::Add(columns[ix], hn::IfThenElseZero(in, hn::Mul(gx[ix], gy[iy])));
            }
        }
        const V sum = hn::Add(hn::Add(hn::Add(columns[0], columns[1]), hn::Add(columns[2], columns[3])),
                              hn::Add(hn::Add(columns[4], columns[5]), hn::Add(columns[6], columns[7])));
        hn::Store(sum, d, sums + i);
        hn::Store(hn::Div(hn::Set(d, 1.f), sum), d, P.norm + i);
    }
}

void ProjectPoints(const SplatLanes& L, PointLanes& P, size_t n, const PointLaneContext& ctx) {
    constexpr size_t kVector = 16;  // PointSums' widest vector (and twice PointBoxes'): m is a whole number of them
    static_assert(kSplatLanes % kVector == 0);
    const size_t m = (n + kVector - 1) / kVector * kVector;
    PointBoxes(L, P, m, ctx);
    bool any = false;
    for (size_t k = 0; k < n; ++k) any |= P.status[k] == PointLanes::kPoint;
    if (!any) return;
    alignas(64) float sums[kSplatLanes];
    PointSums(P, m, sums);
    // finishPointSetup's one-pixel fallback (an empty sum) stays with the scalar path.
    for (size_t k = 0; k < n; ++k)
        if (P.status[k] == PointLanes::kPoint && !(sums[k] > 0.f)) P.status[k] = PointLanes::kScalar;
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
HWY_EXPORT(ProjectPoints);
HWY_EXPORT(SlabsOf);

void projectPointsVector(const SplatLanes& in, PointLanes& out, size_t n, const PointLaneContext& ctx) {
    HWY_DYNAMIC_DISPATCH(ProjectPoints)(in, out, n, ctx);
}

void slabsOf(const float* distance, size_t n, double slabLength, int64_t first, int64_t last, int64_t* slab) {
    HWY_DYNAMIC_DISPATCH(SlabsOf)(distance, n, slabLength, first, last, slab);
}

void projectSplatsVector(SplatLanes& lanes, size_t n, const SplatLaneContext& ctx) {
    HWY_DYNAMIC_DISPATCH(ProjectSplats)(lanes, n, ctx);
}

void SplatLanes::exactMapInto(size_t i, ExactIndexMap& m) const {
    m.w0 = float(map[0][i]), m.wx = float(map[1][i]), m.wy = float(map[2][i]);
    m.wxx = float(map[3][i]), m.wxy = float(map[4][i]), m.wyy = float(map[5][i]);
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
