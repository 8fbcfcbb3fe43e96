// shading/shade_leaf.cpp — shadeLeafRows with Google Highway (see shade_leaf.h). Compiled once per
// SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU has. Compiled
// without contraction (CMakeLists.txt): every expression is the one of shading.cpp and
// shading_field.cpp it mirrors (glm's sums left to right, its mat4 · vec4 as (m₀x + m₁y) +
// (m₂z + m₃)), operation for operation, so the factors are the scalar ones bit for bit.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "shading/shade_leaf.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "shading/shade_leaf.h"
#include "volume/classify-inl.h"

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using RowTag = hn::CappedTag<float, 8>;  // one row of the leaf: 8 voxels along z

bool LeafShadingSupported() {
#if HWY_TARGET == HWY_SCALAR
    return false;
#else
    return hn::Lanes(RowTag()) == 8;
#endif
}

/// The rows, for targets whose RowTag holds 8 lanes (a template, so that the others never
/// instantiate a body whose halves they cannot name).
template <class D>
void ShadeRows(D d, const LeafShadingInput& in, LeafFactors& out) {
#if HWY_TARGET != HWY_SCALAR
    if constexpr (hn::MaxLanes(D()) == 8) {
        using V = hn::Vec<D>;
        const hn::Half<D> dh;                        // 4 floats
        const hn::Rebind<double, decltype(dh)> dd;   // 4 doubles
        const hn::Rebind<int32_t, decltype(dh)> di;  // 4 ints
        using VD = hn::Vec<decltype(dd)>;
        const ShadingSettings& s = in.settings;
        const glm::dmat4& M = in.indexToWorld;
        const glm::mat3& A = in.gradientToWorld;
        const V zero = hn::Zero(d), one = hn::Set(d, 1.f), half = hn::Set(d, 0.5f);
        // (x + y) + z: glm's dot, length and the rows of its matrix products.
        const auto sum3 = [](auto x, auto y, auto z) { return hn::Add(hn::Add(x, y), z); };
        const auto dot3 = [&](V ax, V ay, V az, V bx, V by, V bz) {
            return sum3(hn::Mul(ax, bx), hn::Mul(ay, by), hn::Mul(az, bz));
        };
        // std::clamp(t, 0, 1) as it is written, (t < 0) ? 0 : (1 < t) ? 1 : t (NaN stays NaN).
        const auto clamp01 = [&](V t) { return hn::IfThenElse(hn::Lt(t, zero), zero, hn::IfThenElse(hn::Lt(one, t), one, t)); };
        // Per half h of a row, m₂Z + m₃ of its lanes (Z = origin.z + z): the same for every row.
        VD zPart[2][3];
        for (int h = 0; h < 2; ++h) {
            const VD z = hn::PromoteTo(dd, hn::Add(hn::Iota(di, 4 * h), hn::Set(di, in.origin.z)));
            for (int c = 0; c < 3; ++c) zPart[h][c] = hn::Add(hn::Mul(hn::Set(dd, M[2][c]), z), hn::Set(dd, M[3][c]));
        }
        const glm::dvec3 eye = in.eye;
        const V lx = hn::Set(d, in.toLight.x), ly = hn::Set(d, in.toLight.y), lz = hn::Set(d, in.toLight.z);
        const V ambient = hn::Set(d, s.ambient), diffuse = hn::Set(d, s.diffuse), specular = hn::Set(d, s.specular);
        const bool phong = s.mode == ShadingMode::Phong;
        constexpr int kS = 10;  // the padded grid's side
        // The normalised values on the padded grid (voxel (x, y, z) at ((x+1)·10 + y+1)·10 + z+1): the
        // leaf's rows (an inactive voxel reads as the background), then the faces' layers, each
        // normalised as gradientOf does, (v − lo)·scale clamped to [0, 1].
        alignas(64) float padded[kS * kS * kS];
        const V lo = hn::Set(d, in.lo), scale = hn::Set(d, in.scale), background = hn::Set(d, in.background);
        const auto normalised = [&](V v) { return clamp01(hn::Mul(hn::Sub(v, lo), scale)); };
        const auto rowMask = [&](int n) {  // the active lanes of row n / 8
            uint8_t byte[8] = {uint8_t(in.maskWords[n >> 6] >> (n & 63))};
            return hn::LoadMaskBits(d, byte);
        };
        for (int n = 0; n < 512; n += 8) {
            const V v = hn::IfThenElse(rowMask(n), hn::LoadU(d, in.values + n), background);
            hn::StoreU(normalised(v), d, padded + ((n >> 6) + 1) * kS * kS + (((n >> 3) & 7) + 1) * kS + 1);
        }
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                alignas(32) float layer[64];
                for (int k = 0; k < 64; k += 8) hn::Store(normalised(hn::LoadU(d, in.faces[2 * axis + side] + k)), d, layer + k);
                for (int u = 0; u < 8; ++u)
                    for (int v = 0; v < 8; ++v) {
                        int c[3];
                        c[axis] = side == 0 ? 0 : kS - 1, c[(axis + 1) % 3] = u + 1, c[(axis + 2) % 3] = v + 1;
                        padded[(c[0] * kS + c[1]) * kS + c[2]] = layer[u * 8 + v];
                    }
            }
        // Rows and lanes the table may draw: active, and the table index not below transparentBelow.
        const ClassifyLanes<D> classify(d, *in.table);
        alignas(32) float powBase[8], magnitudes[8];
        for (int x = 0; x < 8; ++x)
            for (int y = 0; y < 8; ++y) {
                const int n = x * 64 + y * 8;
                const V value = hn::LoadU(d, in.values + n);
                const auto active = hn::And(hn::IsFinite(value), rowMask(n));
                const auto drawn = hn::AndNot(hn::Lt(classify.Index(value, active), classify.transparent), active);
                if (hn::AllFalse(d, drawn)) {  // nothing here is drawn: unshaded
                    hn::Store(one, d, out.diffuse + n), hn::Store(zero, d, out.specular + n), hn::Store(one, d, out.opacity + n);
                    continue;
                }
                const float* row = padded + ((x + 1) * kS + (y + 1)) * kS + 1;  // voxel (x, y, 0)
                // centralDifference: 0.5·(n₊ − n₋) per axis, from the normalised neighbours.
                const V gx = hn::Mul(half, hn::Sub(hn::LoadU(d, row + kS * kS), hn::LoadU(d, row - kS * kS)));
                const V gy = hn::Mul(half, hn::Sub(hn::LoadU(d, row + kS), hn::LoadU(d, row - kS)));
                const V gz = hn::Mul(half, hn::Sub(hn::LoadU(d, row + 1), hn::LoadU(d, row - 1)));
                const V magnitude = hn::Sqrt(dot3(gx, gy, gz, gx, gy, gz));
                // toEye: (eye − x)/|eye − x| in double, x = indexToWorld · (X, Y, Z, 1), then float.
                V ex, ey, ez;
                {
                    const double X = double(in.origin.x + x), Y = double(in.origin.y + y);
                    VD t[2][3], length[2];
                    for (int h = 0; h < 2; ++h) {
                        for (int c = 0; c < 3; ++c)
                            t[h][c] = hn::Sub(hn::Set(dd, eye[c]), hn::Add(hn::Set(dd, M[0][c] * X + M[1][c] * Y), zPart[h][c]));
                        length[h] = hn::Sqrt(sum3(hn::Mul(t[h][0], t[h][0]), hn::Mul(t[h][1], t[h][1]), hn::Mul(t[h][2], t[h][2])));
                    }
                    const auto unit = [&](int c) {
                        VD u[2];
                        for (int h = 0; h < 2; ++h)
                            u[h] = hn::IfThenElseZero(hn::Gt(length[h], hn::Zero(dd)), hn::Div(t[h][c], length[h]));
                        return hn::Combine(d, hn::DemoteTo(dh, u[1]), hn::DemoteTo(dh, u[0]));
                    };
                    ex = unit(0), ey = unit(1), ez = unit(2);
                }
                // shadeVoxel: the weight, the world gradient's direction turned to the eye.
                const V weight = phong ? [&] {
                    const V t = clamp01(hn::Div(magnitude, hn::Set(d, kFullShadingGradient)));
                    return hn::Mul(hn::Mul(t, t), hn::Sub(hn::Set(d, 3.f), hn::Mul(hn::Set(d, 2.f), t)));
                }() : zero;
                const auto row3 = [&](int r) {
                    return sum3(hn::Mul(hn::Set(d, A[0][r]), gx), hn::Mul(hn::Set(d, A[1][r]), gy), hn::Mul(hn::Set(d, A[2][r]), gz));
                };
                const V wx = row3(0), wy = row3(1), wz = row3(2);
                const V length = hn::Sqrt(dot3(wx, wy, wz, wx, wy, wz));
                const auto shaded = hn::And(hn::Gt(weight, zero), hn::Gt(length, zero));
                V nx = hn::Div(hn::Neg(wx), length), ny = hn::Div(hn::Neg(wy), length), nz = hn::Div(hn::Neg(wz), length);
                const auto away = hn::Lt(dot3(nx, ny, nz, ex, ey, ez), zero);
                nx = hn::IfThenElse(away, hn::Neg(nx), nx), ny = hn::IfThenElse(away, hn::Neg(ny), ny),
                nz = hn::IfThenElse(away, hn::Neg(nz), nz);
                const V tlx = in.settings.hasLight ? lx : ex, tly = in.settings.hasLight ? ly : ey,
                        tlz = in.settings.hasLight ? lz : ez;
                const V nl = dot3(nx, ny, nz, tlx, tly, tlz);
                const auto lit = hn::Gt(nl, zero);
                const V dTerm = hn::IfThenElse(lit, hn::Add(ambient, hn::Mul(diffuse, nl)), ambient);
                const V hx = hn::Add(tlx, ex), hy = hn::Add(tly, ey), hz = hn::Add(tlz, ez);
                const V hl = hn::Sqrt(dot3(hx, hy, hz, hx, hy, hz));
                const V cosine = hn::Div(dot3(nx, ny, nz, hx, hy, hz), hl);
                // std::max(0, c) as it is written, (0 < c) ? c : 0 (NaN gives 0).
                hn::Store(hn::IfThenElseZero(hn::Lt(zero, cosine), cosine), d, powBase);
                const auto specularLanes = hn::And(drawn, hn::And(shaded, hn::And(lit, hn::Gt(hl, zero))));
                alignas(32) float power[8] = {};
                uint8_t bits[8] = {};  // specularLanes
                hn::StoreMaskBits(d, specularLanes, bits);
                for (unsigned m = bits[0]; m != 0; m &= m - 1) {  // libm's powf, per lane that needs it
                    const int z = std::countr_zero(m);
                    power[z] = std::pow(powBase[z], s.shininess);
                }
                const V spec = hn::Mul(specular, hn::Load(d, power));  // 0 where not lit: k_s · 0
                const auto lighted = hn::And(drawn, shaded);  // the rest: (1, 0, G), or (1, 0, 1) where not drawn
                hn::Store(hn::IfThenElse(lighted, hn::Add(one, hn::Mul(weight, hn::Sub(dTerm, one))), one), d, out.diffuse + n);
                hn::Store(hn::IfThenElseZero(lighted, hn::Mul(weight, spec)), d, out.specular + n);
                hn::Store(one, d, out.opacity + n);
                if (s.gradientOpacity > 0.f) {  // libm's expm1, per lane drawn
                    hn::Store(magnitude, d, magnitudes);
                    uint8_t bits[8] = {};
                    hn::StoreMaskBits(d, drawn, bits);
                    for (unsigned m = bits[0]; m != 0; m &= m - 1) {
                        const int z = std::countr_zero(m);
                        out.opacity[n + z] = gradientOpacityFactor(magnitudes[z], s.gradientOpacity);
                    }
                }
            }
    } else
#endif
    {
        (void)d, (void)in, (void)out;
    }
}

void ShadeLeafRowsImpl(const LeafShadingInput& in, LeafFactors& out) { ShadeRows(RowTag(), in, out); }

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(ShadeLeafRowsImpl);
HWY_EXPORT(LeafShadingSupported);

bool leafShadingSupported() { return HWY_DYNAMIC_DISPATCH(LeafShadingSupported)(); }

void shadeLeafRows(const LeafShadingInput& in, LeafFactors& out) { HWY_DYNAMIC_DISPATCH(ShadeLeafRowsImpl)(in, out); }

}  // namespace vdbsplat
#endif  // HWY_ONCE
