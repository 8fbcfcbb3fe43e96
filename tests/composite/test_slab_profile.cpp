// tests/composite/test_slab_profile.cpp — the slab fractions of --compositing slabs
// (composite/slab_profile.h) against brute-force integration of the kernel along rays.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "composite/slab_profile.h"
#include "footprint/kernel.h"
#include "support/targets.h"

namespace vdbsplat {
namespace {

/// ∫ g along the ray at distance @p rho (voxels) from the kernel centre, over the ray
/// parameter t ∈ [a, b) measured from the closest approach (midpoint rule, fine steps).
double lineIntegral(const KernelShape& k, double rho, double a, double b, int steps = 4000) {
    const double dt = (b - a) / steps;
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double t = a + (i + 0.5) * dt;
        sum += k.value(rho * rho + t * t);
    }
    return sum * dt;
}

// C(x) is the kernel's marginal: its derivative is ∫∫ g over the plane at x (brute force in
// polar coordinates), it runs from 0 at −R to 1 at R, and it is odd about ½.
TEST(SlabProfile, MarginalCdfIsTheKernelsMassBelowAPlane) {
    for (const KernelShape* k : {&KernelShape::standard(), &KernelShape::sharp()}) {
        const double R = k->radius();
        EXPECT_EQ(kernelMarginalCdf(*k, -R), 0.0);
        EXPECT_NEAR(kernelMarginalCdf(*k, R - 1e-12), 1.0, 1e-9) << k->id();
        EXPECT_NEAR(kernelMarginalCdf(*k, 0.0), 0.5, 1e-12) << k->id();
        for (const double x : {-1.7, -1.0, -0.3, 0.2, 0.9, 1.4}) {
            if (std::abs(x) >= R) continue;
            const double h = 1e-4;
            const double density = (kernelMarginalCdf(*k, x + h) - kernelMarginalCdf(*k, x - h)) / (2 * h);
            // ∫∫ g(ρ² + x²) 2πρ dρ over ρ < √(R² − x²)
            const int n = 20000;
            const double top = std::sqrt(R * R - x * x);
            double plane = 0.0;
            for (int i = 0; i < n; ++i) {
                const double rho = (i + 0.5) * top / n;
                plane += k->value(rho * rho + x * x) * 2.0 * M_PI * rho * top / n;
            }
            EXPECT_NEAR(density, plane, 2e-6) << k->id() << " x " << x;
            EXPECT_NEAR(kernelMarginalCdf(*k, -x), 1.0 - kernelMarginalCdf(*k, x), 1e-12);
        }
    }
}

// The fractions of one primitive are what the kernel deposits in each slab: summed over the
// footprint (every ray, weighted by its area 2πρ dρ) they equal the brute-force mass of the kernel
// in each slab, for a kernel far enough that radial slabs are planes (D = 10⁴ voxels), centres
// anywhere in their slab, slabs of one and of half a voxel.
TEST(SlabProfile, FractionsAreTheKernelsMassPerSlabSummedOverTheFootprint) {
    const KernelShape& k = KernelShape::standard();
    const double R = k.radius();
    for (const double slab : {1.0, 0.5}) {
        const int reach = slabReachFor(R / slab);
        EXPECT_EQ(reach, slab == 1.0 ? 2 : 4);
        for (const double offset : {0.0, 0.13, 0.5, 0.87}) {
            const SlabProfile p = slabFractions(k, offset, 1.0 / slab, reach);
            double sum = 0.0;
            for (int j = 0; j <= 2 * reach; ++j) {
                // slab j covers t ∈ [(j − K − offset)·slab, (j − K + 1 − offset)·slab) from the centre
                const double a = (j - reach - offset) * slab, b = a + slab;
                const int n = 400;
                double mass = 0.0;
                for (int i = 0; i < n; ++i) {
                    const double rho = (i + 0.5) * R / n;
                    mass += lineIntegral(k, rho, std::max(a, -R), std::min(std::max(b, -R), R), 800) * 2.0 * M_PI * rho * R / n;
                }
                EXPECT_NEAR(p.fraction[size_t(j)], mass, 2e-5) << "slab " << slab << " offset " << offset << " j " << j;
                sum += p.fraction[size_t(j)];
            }
            EXPECT_NEAR(sum, 1.0, 1e-6);
        }
    }
}

// One ray at a time the profile is the 1-D Gaussian truncated at ±√(R² − ρ²), centred at the
// closest approach √(D² − ρ²) from the eye: the per-primitive fractions (uniform over the footprint)
// are off from the ray's own by the truncation and the centring. Measured here (and in
// docs/compositing.md): the largest difference of any slab's fraction, weighted by the ray's share
// of the footprint's deposit F(ρ)·2πρ, for D = 20 and 200 voxels.
TEST(SlabProfile, PerRayProfileDiffersLittleFromTheFootprintsOwn) {
    const KernelShape& k = KernelShape::standard();
    const double R = k.radius();
    for (const double D : {20.0, 200.0}) {
        for (const double slab : {1.0, 0.5}) {
            const int reach = slabReachFor(R / slab);
            const double offset = 0.37;
            const SlabProfile p = slabFractions(k, offset, 1.0 / slab, reach);
            double worstWeighted = 0.0, worstCentral = 0.0;
            const int n = 200;
            for (int i = 0; i < n; ++i) {
                const double rho = (i + 0.5) * R / n;
                const double F = k.footprint(rho);
                const double shift = D - std::sqrt(D * D - rho * rho);  // the closest approach is nearer the eye
                for (int j = 0; j <= 2 * reach; ++j) {
                    const double a = (j - reach - offset) * slab + shift, b = a + slab;
                    const double ray = lineIntegral(k, rho, std::clamp(a, -R, R), std::clamp(b, -R, R), 2000) / F;
                    const double diff = std::abs(ray - p.fraction[size_t(j)]);
                    worstWeighted = std::max(worstWeighted, diff * F / k.footprint(0.0));
                    if (rho < 0.5) worstCentral = std::max(worstCentral, diff);
                }
            }
            std::printf("  D %5.0f voxels, slabs %.1f voxel: per-ray fraction error within ρ < 0.5: %.4f; "
                        "weighted by F(ρ)/F(0): %.4f\n", D, slab, worstCentral, worstWeighted);
            EXPECT_LT(worstCentral, 0.01) << D << " " << slab;
            EXPECT_LT(worstWeighted, 0.01) << D << " " << slab;
        }
    }
}

// The projection's tabulated C(x) against the closed form, and the fractions it gives.
TEST(SlabProfile, TabulatedMarginalMatchesTheClosedForm) {
    for (const KernelShape* k : {&KernelShape::standard(), &KernelShape::sharp()}) {
        const MarginalCdfTable table(*k);
        double worst = 0.0;
        for (int i = 0; i <= 100000; ++i) {
            const double x = -2.5 + 5.0 * i / 100000;
            worst = std::max(worst, std::abs(table(x) - kernelMarginalCdf(*k, x)));
        }
        std::printf("  %s: tabulated C(x) max error %.2e\n", k->id(), worst);
        EXPECT_LT(worst, 1e-7) << k->id();
        for (const double offset : {0.0, 0.3, 0.99}) {
            const SlabProfile a = slabFractions(*k, offset, 2.0, 4), b = slabFractions(table, offset, 2.0, 4);
            for (int j = 0; j < kMaxSlabSpan; ++j) EXPECT_NEAR(a.fraction[size_t(j)], b.fraction[size_t(j)], 3e-7);
        }
    }
}

// The energy rule (DESIGN §4): every primitive's fractions sum to 1 in float, whatever its
// centre, its width (aggregates whose profile reaches past K slabs are truncated and renormalised),
// or a cut at the eye.
TEST(SlabProfile, FractionsSumToOne) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 2000; ++i) {
        const int reach = 1 + int(u(rng) * kMaxSlabReach);
        const double offset = -0.2 + 1.4 * u(rng), unit = 0.1 + 6.0 * u(rng);
        const int lowest = u(rng) < 0.2 ? -int(u(rng) * reach) : -kMaxSlabReach;
        const SlabProfile p = slabFractions(KernelShape::standard(), offset, unit, reach, lowest);
        float sum = 0.f;
        for (int j = 0; j < kMaxSlabSpan; ++j) {
            EXPECT_GE(p.fraction[size_t(j)], 0.f);
            if (j > 2 * reach || j < reach + lowest) {
                EXPECT_EQ(p.fraction[size_t(j)], 0.f) << j;
            }
            sum += p.fraction[size_t(j)];
        }
        EXPECT_NEAR(sum, 1.f, 4e-7f) << offset << " " << unit << " " << reach;
    }
}

// The projection's vector fractions (slabFractionsBatch) are the scalar slabFractions' bit for
// bit, on every SIMD target the binary holds: centres in and outside their slab, units from
// a tenth of a slab (narrower than 1e−12, and 0 and NaN: the scalar's std::max) to wide aggregates,
// every reach, cuts at the eye, batch lengths that leave a partial last vector, and a centre so far
// out that nothing is within reach (all in its own slab).
TEST(SlabProfile, BatchEqualsTheScalarFractionsBitForBit) {
    test::forEachTarget([] {
        for (const KernelShape* k : {&KernelShape::standard(), &KernelShape::sharp()}) {
            const MarginalCdfTable table(*k);
            std::mt19937 rng(11);
            std::uniform_real_distribution<double> u(0.0, 1.0);
            for (int reach = 0; reach <= kMaxSlabReach; ++reach)
                for (const size_t n : {size_t(1), size_t(7), size_t(64)}) {
                    std::vector<double> offset(n), unit(n);
                    std::vector<int> lowest(n);
                    for (size_t i = 0; i < n; ++i) {
                        offset[i] = -0.3 + 1.6 * u(rng);
                        unit[i] = 0.1 + 6.0 * u(rng);
                        lowest[i] = u(rng) < 0.3 ? -int(u(rng) * (reach + 1)) : -kMaxSlabReach;
                    }
                    offset[0] = 0.5;  // an exact slab centre
                    if (n > 2) offset[1] = 40.0, unit[2] = 0.0;  // nothing within reach; a zero unit
                    if (n > 4) unit[3] = std::nan(""), unit[4] = 1e-13;
                    std::vector<SlabProfile> batch(n);
                    slabFractionsBatch(table, offset.data(), unit.data(), lowest.data(), n, reach, batch.data());
                    for (size_t i = 0; i < n; ++i) {
                        const SlabProfile scalar = slabFractions(table, offset[i], unit[i], reach, lowest[i]);
                        for (int j = 0; j < kMaxSlabSpan; ++j)
                            ASSERT_EQ(std::bit_cast<uint32_t>(batch[i].fraction[size_t(j)]),
                                      std::bit_cast<uint32_t>(scalar.fraction[size_t(j)]))
                                << k->id() << " reach " << reach << " i " << i << " slab " << j << ": offset " << offset[i]
                                << " unit " << unit[i] << " lowest " << lowest[i];
                    }
                }
        }
    });
}

}  // namespace
}  // namespace vdbsplat
