// pointfilter/point_filter.cpp — the point's circular filter and energy rule (DESIGN §4;
// see point_filter.h).
#include "pointfilter/point_filter.h"

#include <algorithm>
#include <cmath>

#include "footprint/kernel.h"
#include "footprint/prefilter.h"

namespace vdbsplat {

double pointFilterVariance(double projectedSpacingPx, double prefilterVariance, double kernelSigma) {
    const double s = kernelSigma * projectedSpacingPx;
    return prefilterVariance + s * s;
}

double pointDepositTotal(double sigma, double h, double f, const ViewPoint& c) {
    if (!(c.z > 0.0)) return 0.0;
    const double M = h * h * h;
    const double fz = f / c.z;
    return sigma * M * fz * fz * (glm::length(c) / c.z);
}

double point_filter_weight::maxAbsError() {
    constexpr int kSamples = 16384;
    double worst = 0.0;
    for (int k = 0; k < kSamples; ++k) {
        const float x = static_cast<float>(kMaxX * k / kSamples);
        worst = std::max(worst, std::abs(pointFilterWeight(x) - std::exp(-0.5 * x)));
    }
    return worst;
}

namespace {
/// First and last pixel index whose centre i + 0.5 lies strictly within @p rs of @p x.
void centresWithin(double x, double rs, int& first, int& count) {
    first = static_cast<int>(std::floor(x - 0.5 - rs)) + 1;
    const int last = static_cast<int>(std::ceil(x - 0.5 + rs)) - 1;
    count = std::clamp(last - first + 1, 0, kPointMaxSide);
}
}  // namespace

PointFootprint rasterizePoint(const PixelCoord& x, double variance) {
    PointFootprint out;
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !(variance > 0.0) || x.x < -1e9 || x.x > 1e9 ||
        x.y < -1e9 || x.y > 1e9)
        return out;
    const double rs = std::min(kPointSupportSigmas * std::sqrt(variance), kPointMaxRadiusPx);
    centresWithin(x.x, rs, out.x0, out.nx);
    centresWithin(x.y, rs, out.y0, out.ny);
    // The Gaussian is separable, exp(−(dx² + dy²)/2V) = exp(−dx²/2V)·exp(−dy²/2V): one weight
    // per column and per row (≤ 14, not ≤ 49); the support stays the circle r < r_s.
    const float invV = static_cast<float>(1.0 / variance), rs2 = static_cast<float>(rs * rs);
    std::array<float, kPointMaxSide> dxs{}, gx{}, gy{};
    for (int ix = 0; ix < out.nx; ++ix) {
        dxs[ix] = static_cast<float>(out.x0 + ix + 0.5 - x.x);
        gx[ix] = pointFilterWeight(dxs[ix] * dxs[ix] * invV);
    }
    std::array<float, kPointSumColumns> columns{};
    for (int iy = 0; iy < out.ny; ++iy) {
        const float dy = static_cast<float>(out.y0 + iy + 0.5 - x.y), dy2 = dy * dy;
        gy[iy] = pointFilterWeight(dy2 * invV);
        for (int ix = 0; ix < out.nx; ++ix) {
            const float w = dxs[ix] * dxs[ix] + dy2 < rs2 ? gx[ix] * gy[iy] : 0.0f;
            out.w[iy * out.nx + ix] = w;
            columns[size_t(ix)] += w;
        }
    }
    const float sum = sumColumnsPairwise(columns.data());
    if (sum > 0.0f) {
        const float inv = 1.0f / sum;
        for (int k = 0; k < out.nx * out.ny; ++k) out.w[k] *= inv;
    } else {  // cannot happen for V ≥ kPrefilterVariance; keep the energy anyway
        out.x0 = static_cast<int>(std::floor(x.x)), out.y0 = static_cast<int>(std::floor(x.y));
        out.nx = out.ny = 1;
        out.w[0] = 1.0f;
    }
    return out;
}

namespace {
/// floor and ceil of a finite |v| < 2³¹ by an integer cast and a compare (std::floor and
/// std::ceil are libm calls on the x86-64 baseline); exact, so the same integers.
int floorSmall(double v) {
    const int i = static_cast<int>(v);
    return i - (static_cast<double>(i) > v ? 1 : 0);
}
int ceilSmall(double v) {
    const int i = static_cast<int>(v);
    return i + (static_cast<double>(i) < v ? 1 : 0);
}
}  // namespace

bool pointSetupBox(const PixelCoord& x, double variance, PointSetup& s, float& invV, float& rs2) {
    s = PointSetup{};
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !(variance > 0.0) || x.x < -1e9 || x.x > 1e9 ||
        x.y < -1e9 || x.y > 1e9)
        return false;
    const double rs = std::min(kPointSupportSigmas * std::sqrt(variance), kPointMaxRadiusPx);
    s.x0 = floorSmall(x.x - 0.5 - rs) + 1, s.nx = std::clamp(ceilSmall(x.x - 0.5 + rs) - 1 - s.x0 + 1, 0, kPointMaxSide);
    s.y0 = floorSmall(x.y - 0.5 - rs) + 1, s.ny = std::clamp(ceilSmall(x.y - 0.5 + rs) - 1 - s.y0 + 1, 0, kPointMaxSide);
    invV = static_cast<float>(1.0 / variance), rs2 = static_cast<float>(rs * rs);
    return true;
}

void finishPointSetup(PointSetup& s, const PixelCoord& x, float sum, float invV, float rs2) {
    if (sum > 0.0f) {
        s.invVariance = invV, s.radius2 = rs2, s.norm = 1.0f / sum;
    } else {  // rasterizePoint's fallback: one pixel of weight weight(0)·weight(0)·1 = 1
        s.x0 = floorSmall(x.x), s.y0 = floorSmall(x.y);
        s.nx = s.ny = 1;
        s.invVariance = 0.0f, s.radius2 = INFINITY, s.norm = 1.0f;
    }
}

PointSetup setupPoint(const PixelCoord& x, double variance) {
    // rasterizePoint's footprint and its sum, in its order (sumColumnsPairwise; a term outside
    // the circle is +0 there and changes no sum), without storing the weights.
    PointSetup s;
    float invV = 0.0f, rs2 = 0.0f;
    if (!pointSetupBox(x, variance, s, invV, rs2)) return s;
    std::array<float, kPointMaxSide> dx2{}, gx{};
    for (int ix = 0; ix < s.nx; ++ix) {
        const float dx = static_cast<float>(s.x0 + ix + 0.5 - x.x);
        dx2[size_t(ix)] = dx * dx;
        gx[size_t(ix)] = pointFilterWeight(dx * dx * invV);
    }
    std::array<float, kPointSumColumns> columns{};
    for (int iy = 0; iy < s.ny; ++iy) {
        const float dy = static_cast<float>(s.y0 + iy + 0.5 - x.y), dy2 = dy * dy;
        const float gy = pointFilterWeight(dy2 * invV);
        for (int ix = 0; ix < s.nx; ++ix) {  // branch-free: which pixels the circle keeps varies point by point
            const float w = gx[size_t(ix)] * gy;
            columns[size_t(ix)] += dx2[size_t(ix)] + dy2 < rs2 ? w : 0.0f;
        }
    }
    finishPointSetup(s, x, sumColumnsPairwise(columns.data()), invV, rs2);
    return s;
}

}  // namespace vdbsplat
