// composite/slab_profile.cpp — the slab fractions of one kernel (see slab_profile.h).
#include "composite/slab_profile.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vdbsplat {

namespace {
double Phi(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }
}  // namespace

double kernelMarginalCdf(const KernelShape& kernel, double x) {
    const double s = kernel.sigma(), R = kernel.radius();
    if (x <= -R) return 0.0;
    if (x >= R) return 1.0;
    // C(x) = N·2πs²·[s√(2π)(Φ(x/s) − Φ(−R/s)) − exp(−R²/2s²)(x + R)]  (slab_profile.h)
    const double twoPi = 2.0 * std::numbers::pi;
    const double gauss = s * std::sqrt(twoPi) * (Phi(x / s) - Phi(-R / s));
    const double floorTerm = std::exp(-R * R / (2.0 * s * s)) * (x + R);
    return std::clamp(kernel.normalization() * twoPi * s * s * (gauss - floorTerm), 0.0, 1.0);
}

MarginalCdfTable::MarginalCdfTable(const KernelShape& kernel)
    : radius_(kernel.radius()), scale_(double(kIntervals) / (2.0 * kernel.radius())) {
    for (int i = 0; i <= kIntervals; ++i) value_[size_t(i)] = kernelMarginalCdf(kernel, -radius_ + double(i) / scale_);
}

template <class Cdf>
SlabProfile slabFractionsOf(const Cdf& cdf, double offset, double unitInSlabs, int reach, int lowest) {
    SlabProfile p;
    reach = std::clamp(reach, 0, kMaxSlabReach);
    const double inv = 1.0 / std::max(unitInSlabs, 1e-12);
    double sum = 0.0;
    std::array<double, kMaxSlabSpan> f{};
    // slab s + r covers [r, r + 1) slab lengths from the start of slab s; the kernel centre is at `offset`
    const int first = std::max(-reach, lowest);
    double lo = cdf((double(first) - offset) * inv);
    for (int r = first; r <= reach; ++r) {
        const double hi = cdf((double(r) + 1.0 - offset) * inv);
        f[size_t(r + reach)] = std::max(hi - lo, 0.0);
        sum += f[size_t(r + reach)];
        lo = hi;
    }
    if (!(sum > 0.0)) {  // nothing within reach (a centre far outside its slab): all in its own slab
        p.fraction[size_t(reach)] = 1.f;
        return p;
    }
    // One division: f·(1/sum) in double is within an ulp of f/sum, so the float fractions are the
    // quotient's but where that ulp straddles a float's rounding boundary (~2⁻²⁸ of them).
    const double invSum = 1.0 / sum;
    for (int j = 0; j <= 2 * reach; ++j) p.fraction[size_t(j)] = float(f[size_t(j)] * invSum);
    return p;
}

SlabProfile slabFractions(const KernelShape& kernel, double offset, double unitInSlabs, int reach, int lowest) {
    return slabFractionsOf([&](double x) { return kernelMarginalCdf(kernel, x); }, offset, unitInSlabs, reach, lowest);
}

SlabProfile slabFractions(const MarginalCdfTable& cdf, double offset, double unitInSlabs, int reach, int lowest) {
    return slabFractionsOf(cdf, offset, unitInSlabs, reach, lowest);
}

int slabReachFor(double radiusInSlabs) {
    return std::clamp(int(std::ceil(radiusInSlabs - 1e-9)), 0, kMaxSlabReach);
}

}  // namespace vdbsplat
