// footprint/kernel.cpp — closed forms of the truncated Gaussian kernels (see kernel.h).
#include "footprint/kernel.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "util/error.h"

namespace vdbsplat {

namespace {
/// ∫_{|x|<R} exp(−|x|²/2s²) dV = (2π s²)^{3/2} · P(χ₃ < R/s), with
/// P(χ₃ < a) = erf(a/√2) − √(2/π)·a·exp(−a²/2).
double truncatedMass(double s, double R) {
    const double a = R / s;
    const double chi3 = std::erf(a / std::numbers::sqrt2) -
                        std::sqrt(2.0 / std::numbers::pi) * a * std::exp(-0.5 * a * a);
    return std::pow(2.0 * std::numbers::pi * s * s, 1.5) * chi3;
}
}  // namespace

KernelShape::KernelShape(const char* id, const char* tableName, double sigma, double radius)
    : id_(id), tableName_(tableName), sigma_(sigma), radius_(radius), norm_(1.0 / truncatedMass(sigma, radius)) {}

const KernelShape& KernelShape::standard() {
    static const KernelShape k("gaussian", Kernel::kName, Kernel::kSigma, Kernel::kRadius);
    return k;
}

const KernelShape& KernelShape::sharp() {
    static const KernelShape k("gaussian-sharp", "gaussian-s0.5-R1.55", 0.5, 1.55);
    return k;
}

const KernelShape& KernelShape::named(const std::string& name) {
    if (name == standard().id()) return standard();
    if (name == sharp().id()) return sharp();
    throw Error("--kernel: unknown kernel '" + name + "' (choose " + kNames + ")");
}

double KernelShape::value(double s2) const {
    if (s2 >= radius_ * radius_) return 0.0;
    return norm_ * std::exp(-s2 / (2.0 * sigma_ * sigma_));
}

double KernelShape::segmentIntegral(double rho, double t0, double t1) const {
    const double r2 = radius_ * radius_ - rho * rho;
    if (r2 <= 0.0) return 0.0;
    const double halfChord = std::sqrt(r2);
    const double a = std::clamp(t0, -halfChord, halfChord);
    const double b = std::clamp(t1, -halfChord, halfChord);
    if (b <= a) return 0.0;
    // ∫_a^b N e^{−(ρ²+t²)/2s²} dt = N e^{−ρ²/2s²} · s√(π/2) · (erf(b/(s√2)) − erf(a/(s√2)))
    const double s = sigma_;
    const double scale = s * std::sqrt(std::numbers::pi / 2.0);
    const double inv = 1.0 / (s * std::numbers::sqrt2);
    return norm_ * std::exp(-rho * rho / (2.0 * s * s)) * scale * (std::erf(b * inv) - std::erf(a * inv));
}

double KernelShape::footprintPlaneIntegral(int steps) const {
    // ∫ F dA = ∫_0^R F(ρ) 2πρ dρ, midpoint rule.
    const double dr = radius_ / steps;
    double sum = 0.0;
    for (int k = 0; k < steps; ++k) {
        const double rho = (k + 0.5) * dr;
        sum += footprint(rho) * 2.0 * std::numbers::pi * rho * dr;
    }
    return sum;
}

double KernelShape::volumeIntegral(int n) const {
    const double step = 2.0 * radius_ / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k) {
                const double x = -radius_ + (i + 0.5) * step, y = -radius_ + (j + 0.5) * step,
                             z = -radius_ + (k + 0.5) * step;
                sum += value(x * x + y * y + z * z);
            }
    return sum * step * step * step;
}

double Kernel::normalization() { return KernelShape::standard().normalization(); }

double Kernel::value(double s2) { return KernelShape::standard().value(s2); }

double Kernel::segmentIntegral(double rho, double t0, double t1) {
    return KernelShape::standard().segmentIntegral(rho, t0, t1);
}

double Kernel::footprint(double rho) { return KernelShape::standard().footprint(rho); }

double Kernel::footprintPlaneIntegral(int steps) { return KernelShape::standard().footprintPlaneIntegral(steps); }

}  // namespace vdbsplat
