// volume/cell_records.cpp — cellRecords with Google Highway (see cell_records.h). Compiled once
// per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU has. Compiled
// without contraction (CMakeLists.txt): every expression is the scalar one it mirrors, operation
// for operation.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volume/cell_records.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>

#include "volume/cell_records.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void CellRecordsImpl(const CellFrame& frame, CellLanes& L, int n) {
    const hn::CappedTag<float, CellLanes::kMax> d;
    using V = hn::Vec<decltype(d)>;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.f), halfV = hn::Set(d, 0.5f);
    const glm::mat3& A = frame.toView;
    V a[3][3];  // a[c][r] = A[c][r] (glm: column c, row r)
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) a[c][r] = hn::Set(d, A[c][r]);
    const V ox = hn::Set(d, frame.origin.x), oy = hn::Set(d, frame.origin.y), oz = hn::Set(d, frame.origin.z);
    const V f = hn::Set(d, frame.focal), fullHalf = hn::Set(d, frame.fullMoment * 0.5f);
    // (x + y) + z: glm's dot and the rows of its matrix products.
    const auto sum3 = [](V x, V y, V z) { return hn::Add(hn::Add(x, y), z); };
    for (int i = 0; i < n; i += int(hn::Lanes(d))) {
        // Lanes past n read 0 (never the staging arrays' stale values: no subnormal operands, no
        // uninitialised reads); their results, infinities and NaNs, are not read back.
        const auto live = hn::FirstN(d, size_t(n - i));
        const auto load = [&](const float* p) { return hn::MaskedLoad(live, d, p + i); };
        const V m = load(L.m);
        const V im = hn::Div(one, m);
        // μ = first·(1/m), about the cell's centre; v = origin + A·(cell + μ).
        const V mx = hn::Mul(load(L.fx), im), my = hn::Mul(load(L.fy), im),
                mz = hn::Mul(load(L.fz), im);
        const V qx = hn::Add(load(L.px), mx), qy = hn::Add(load(L.py), my),
                qz = hn::Add(load(L.pz), mz);
        // A·q (mat3 · vec3): row r is A[0][r]·q.x + A[1][r]·q.y + A[2][r]·q.z.
        const auto times = [&](V x, V y, V z, int r) {
            return sum3(hn::Mul(a[0][r], x), hn::Mul(a[1][r], y), hn::Mul(a[2][r], z));
        };
        const V vx = hn::Add(ox, times(qx, qy, qz, 0)), vy = hn::Add(oy, times(qx, qy, qz, 1)),
                vz = hn::Add(oz, times(qx, qy, qz, 2));
        // Covariance about μ (index units²).
        const V cxx = hn::Sub(hn::Mul(load(L.xx), im), hn::Mul(mx, mx));
        const V cyy = hn::Sub(hn::Mul(load(L.yy), im), hn::Mul(my, my));
        const V czz = hn::Sub(hn::Mul(load(L.zz), im), hn::Mul(mz, mz));
        const V cxy = hn::Sub(hn::Mul(load(L.xy), im), hn::Mul(mx, my));
        const V cxz = hn::Sub(hn::Mul(load(L.xz), im), hn::Mul(mx, mz));
        const V cyz = hn::Sub(hn::Mul(load(L.yz), im), hn::Mul(my, mz));
        // uᵀ Σ u with Σ·u (mat3 · vec3, Σ symmetric) then the dot.
        const auto quadratic = [&](V ux, V uy, V uz) {
            const V sx = sum3(hn::Mul(cxx, ux), hn::Mul(cxy, uy), hn::Mul(cxz, uz));
            const V sy = sum3(hn::Mul(cxy, ux), hn::Mul(cyy, uy), hn::Mul(cyz, uz));
            const V sz = sum3(hn::Mul(cxz, ux), hn::Mul(cyz, uy), hn::Mul(czz, uz));
            return sum3(hn::Mul(ux, sx), hn::Mul(uy, sy), hn::Mul(uz, sz));
        };
        // j · A (vec3 · mat3): component c is A[c][0]·j.x + A[c][1]·j.y + A[c][2]·j.z.
        const auto rowTimes = [&](V x, V y, V z, int c) {
            return sum3(hn::Mul(a[c][0], x), hn::Mul(a[c][1], y), hn::Mul(a[c][2], z));
        };
        // J = f/z [I | −v.xy/z] (EWA 2001 eq. 25): rows jx = (fz, 0, −fz·v.x/v.z), jy = (0, fz, −fz·v.y/v.z).
        const V fz = hn::Div(f, vz);
        const V jxz = hn::Div(hn::Mul(hn::Neg(fz), vx), vz), jyz = hn::Div(hn::Mul(hn::Neg(fz), vy), vz);
        const V uxx = rowTimes(fz, zero, jxz, 0), uxy = rowTimes(fz, zero, jxz, 1), uxz = rowTimes(fz, zero, jxz, 2);
        const V uyx = rowTimes(zero, fz, jyz, 0), uyy = rowTimes(zero, fz, jyz, 1), uyz = rowTimes(zero, fz, jyz, 2);
        const V spread = hn::Mul(halfV, hn::Add(quadratic(uxx, uxy, uxz), quadratic(uyx, uyy, uyz)));
        const V distance = hn::Sqrt(sum3(hn::Mul(vx, vx), hn::Mul(vy, vy), hn::Mul(vz, vz)));
        const V ux2 = sum3(hn::Mul(uxx, uxx), hn::Mul(uxy, uxy), hn::Mul(uxz, uxz));
        const V uy2 = sum3(hn::Mul(uyx, uyx), hn::Mul(uyy, uyy), hn::Mul(uyz, uyz));
        const V full = hn::Mul(fullHalf, hn::Add(ux2, uy2));
        hn::Store(vx, d, L.vx + i), hn::Store(vy, d, L.vy + i), hn::Store(vz, d, L.vz + i);
        hn::Store(distance, d, L.distance + i);
        hn::Store(hn::Mul(load(L.er), im), d, L.r + i);
        hn::Store(hn::Mul(load(L.eg), im), d, L.g + i);
        hn::Store(hn::Mul(load(L.eb), im), d, L.b + i);
        hn::Store(hn::Max(hn::Sub(spread, full), zero), d, L.spread + i);
        if (frame.depthSpread) {
            const V wx = hn::Div(vx, distance), wy = hn::Div(vy, distance), wz = hn::Div(vz, distance);
            const V uzx = rowTimes(wx, wy, wz, 0), uzy = rowTimes(wx, wy, wz, 1), uzz = rowTimes(wx, wy, wz, 2);
            hn::Store(hn::Max(quadratic(uzx, uzy, uzz), zero), d, L.depthSpread + i);
        }
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(CellRecordsImpl);

void cellRecords(const CellFrame& frame, CellLanes& lanes, int n) { HWY_DYNAMIC_DISPATCH(CellRecordsImpl)(frame, lanes, n); }

void cellRecordsScalar(const CellFrame& frame, CellLanes& L, int n) {
    const glm::mat3& toView = frame.toView;
    for (int i = 0; i < n; ++i) {
        const float im = 1.f / L.m[i];
        const glm::vec3 mu = glm::vec3(L.fx[i], L.fy[i], L.fz[i]) * im;  // σ-weighted centroid about the cell's centre
        const glm::vec3 v = frame.origin + toView * (glm::vec3(L.px[i], L.py[i], L.pz[i]) + mu);
        // Covariance about μ (index units²), then in view space: Σ_v = A Σ Aᵀ.
        glm::mat3 cov;
        cov[0][0] = L.xx[i] * im - mu.x * mu.x, cov[1][1] = L.yy[i] * im - mu.y * mu.y, cov[2][2] = L.zz[i] * im - mu.z * mu.z;
        cov[0][1] = cov[1][0] = L.xy[i] * im - mu.x * mu.y;
        cov[0][2] = cov[2][0] = L.xz[i] * im - mu.x * mu.z;
        cov[1][2] = cov[2][1] = L.yz[i] * im - mu.y * mu.z;
        // Projected (Jacobian of the perspective map at μ, EWA 2001 eq. 25): J = f/z [I | −v.xy/z];
        // the spread is trace(J A Σ Aᵀ Jᵀ)/2 = Σ over the rows j of J of (Aᵀj)ᵀ Σ (Aᵀj).
        const float fz = frame.focal / v.z;
        const glm::vec3 jx(fz, 0.f, -fz * v.x / v.z), jy(0.f, fz, -fz * v.y / v.z);
        const glm::vec3 ux = jx * toView, uy = jy * toView;  // row vector · A = Aᵀj
        const float spread = 0.5f * (glm::dot(ux, cov * ux) + glm::dot(uy, cov * uy));
        const float distance = glm::length(v);
        L.vx[i] = v.x, L.vy[i] = v.y, L.vz[i] = v.z;
        L.distance[i] = distance;
        L.r[i] = L.er[i] * im, L.g[i] = L.eg[i] * im, L.b[i] = L.eb[i] * im;
        // Only what exceeds a full cell's own second moment (s²·(n² − 1)/12 per index axis)
        // is added: the cells' lattice already spreads a full cell's mass over the cell, as
        // the voxels' lattice does a voxel's (a uniform region of cells is the same quadrature
        // of the same field as its voxels, one level coarser). Adding it again blurred every
        // surface by a cell (docs/animation.md, session 5).
        const float full = frame.fullMoment * 0.5f * (glm::dot(ux, ux) + glm::dot(uy, uy));
        L.spread[i] = std::max(spread - full, 0.f);
        // Along the view ray the whole second moment counts (world²): the depth profile of the
        // cell's mass (--compositing slabs, composite/slab_profile.h), ωᵀ A Σ Aᵀ ω.
        if (frame.depthSpread) {
            const glm::vec3 uz = (v / distance) * toView;
            L.depthSpread[i] = std::max(glm::dot(uz, cov * uz), 0.f);
        }
    }
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
