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

PointFilterTable::PointFilterTable() : v_(kIntervals + 1), scale_(static_cast<float>(kIntervals / kMaxX)) {
    for (int k = 0; k <= kIntervals; ++k) v_[k] = static_cast<float>(std::exp(-0.5 * kMaxX * k / kIntervals));
}

double PointFilterTable::maxAbsError() const {
    constexpr int kSub = 16;
    double worst = 0.0;
    for (int k = 0; k < kIntervals * kSub; ++k) {
        const float x = static_cast<float>(kMaxX * k / (kIntervals * kSub));
        worst = std::max(worst, std::abs(weight(x) - std::exp(-0.5 * x)));
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

PointFootprint rasterizePoint(const PointFilterTable& table, const PixelCoord& x, double variance) {
    PointFootprint out;
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !(variance > 0.0) || x.x < -1e9 || x.x > 1e9 ||
        x.y < -1e9 || x.y > 1e9)
        return out;
    const double rs = std::min(kPointSupportSigmas * std::sqrt(variance), kPointMaxRadiusPx);
    centresWithin(x.x, rs, out.x0, out.nx);
    centresWithin(x.y, rs, out.y0, out.ny);
    // The Gaussian is separable, exp(−(dx² + dy²)/2V) = exp(−dx²/2V)·exp(−dy²/2V): one table
    // lookup per column and per row (≤ 14, not ≤ 49); the support stays the circle r < r_s.
    const float invV = static_cast<float>(1.0 / variance), rs2 = static_cast<float>(rs * rs);
    std::array<float, kPointMaxSide> dxs{}, gx{}, gy{};
    for (int ix = 0; ix < out.nx; ++ix) {
        dxs[ix] = static_cast<float>(out.x0 + ix + 0.5 - x.x);
        gx[ix] = table.weight(dxs[ix] * dxs[ix] * invV);
    }
    float sum = 0.0f;
    for (int iy = 0; iy < out.ny; ++iy) {
        const float dy = static_cast<float>(out.y0 + iy + 0.5 - x.y), dy2 = dy * dy;
        gy[iy] = table.weight(dy2 * invV);
        for (int ix = 0; ix < out.nx; ++ix) {
            const float w = dxs[ix] * dxs[ix] + dy2 < rs2 ? gx[ix] * gy[iy] : 0.0f;
            out.w[iy * out.nx + ix] = w;
            sum += w;
        }
    }
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

}  // namespace vdbsplat
