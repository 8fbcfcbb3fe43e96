// composite/opacity.h — α = 1 − exp(−τ), the one transcendental of the compositor's hot loop.
// Owns: opacityFromOpticalDepth, accurate to a few float ulps over every τ ≥ 0 and about
// 3× cheaper than std::expm1 (which was half of a close-up render's time; measured with
// perf on the Engine at --distance 0.35).
//   τ < 1/32: the Taylor series 1 − e^{−τ} = τ(1 − τ/2(1 − τ/3(1 − τ/4(1 − τ/5)))),
//             truncation error below τ⁶/720 < 1.5e-12 · τ (no cancellation for small τ);
//   τ ≥ 1/32: 1 − expf(−τ); cancellation amplifies expf's ≤ 1 ulp error by at most 1/(1 − e^{−τ}) < 33.
// And takeTransmittance, the scalar "over" step with early termination's remainder.
#pragma once
#include <cmath>

namespace vdbsplat {

inline float opacityFromOpticalDepth(float tau) {
    if (!(tau > 0.f)) return 0.f;
    if (tau < 1.f / 32.f)
        return tau * (1.f - 0.5f * tau * (1.f - tau * (1.f / 3.f) * (1.f - 0.25f * tau * (1.f - 0.2f * tau))));
    return 1.f - std::exp(-tau);
}

/// @brief One deposit of opacity @p alpha on a pixel of transmittance @p T (DESIGN §4), with the
/// remainder (docs/compositing.md, "Early termination and the remainder"): returns the share it
/// takes, T·α, and leaves T − T·α; or, where that would fall below the cutoff @p epsilon, takes
/// all of T and leaves 0. The colour gains the share times the deposit's colour. The vector loops
/// (splat_raster.cpp: Over, CompositeSlabFor) compute the same in the same float operations.
inline float takeTransmittance(float& T, float alpha, float epsilon) {
    const float share = T * alpha, after = T - share;
    if (after >= epsilon) {
        T = after;
        return share;
    }
    const float all = T;
    T = 0.f;
    return all;
}

}  // namespace vdbsplat
