// footprint/kernel.cpp — closed forms of the truncated Gaussian (see kernel.h).
#include "footprint/kernel.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vdbsplat {

namespace {
constexpr double kTwoSigma2 = 2.0 * Kernel::kSigma * Kernel::kSigma;

/// ∫_{|x|<R} exp(−|x|²/2s²) dV = (2π s²)^{3/2} · P(χ₃ < R/s), with
/// P(χ₃ < a) = erf(a/√2) − √(2/π)·a·exp(−a²/2).
double truncatedMass() {
    const double s = Kernel::kSigma;
    const double a = Kernel::kRadius / s;
    const double chi3 = std::erf(a / std::numbers::sqrt2) -
                        std::sqrt(2.0 / std::numbers::pi) * a * std::exp(-0.5 * a * a);
    return std::pow(2.0 * std::numbers::pi * s * s, 1.5) * chi3;
}
}  // namespace

double Kernel::normalization() {
    static const double n = 1.0 / truncatedMass();  // const after first use, thread-safe init
    return n;
}

double Kernel::value(double s2) {
    if (s2 >= kRadius * kRadius) return 0.0;
    return normalization() * std::exp(-s2 / kTwoSigma2);
}

double Kernel::segmentIntegral(double rho, double t0, double t1) {
    const double r2 = kRadius * kRadius - rho * rho;
    if (r2 <= 0.0) return 0.0;
    const double halfChord = std::sqrt(r2);
    const double a = std::clamp(t0, -halfChord, halfChord);
    const double b = std::clamp(t1, -halfChord, halfChord);
    if (b <= a) return 0.0;
    // ∫_a^b N e^{−(ρ²+t²)/2s²} dt = N e^{−ρ²/2s²} · s√(π/2) · (erf(b/(s√2)) − erf(a/(s√2)))
    const double s = kSigma;
    const double scale = s * std::sqrt(std::numbers::pi / 2.0);
    const double inv = 1.0 / (s * std::numbers::sqrt2);
    return normalization() * std::exp(-rho * rho / kTwoSigma2) * scale * (std::erf(b * inv) - std::erf(a * inv));
}

double Kernel::footprint(double rho) {
    return segmentIntegral(rho, -kRadius, kRadius);
}

double Kernel::footprintPlaneIntegral(int steps) {
    // ∫ F dA = ∫_0^R F(ρ) 2πρ dρ, midpoint rule.
    const double dr = kRadius / steps;
    double sum = 0.0;
    for (int k = 0; k < steps; ++k) {
        const double rho = (k + 0.5) * dr;
        sum += footprint(rho) * 2.0 * std::numbers::pi * rho * dr;
    }
    return sum;
}

}  // namespace vdbsplat
