// composite/slab_profile.h — how a primitive's optical depth is spread over the radial depth slabs
// its kernel spans (`--compositing slabs`, docs/compositing.md).
// Owns: SlabProfile (the fractions of one primitive's deposit that go to the slabs s − K … s + K
// around its own slab s), kernelMarginalCdf (the kernel's 1-D marginal along a direction, the
// truncated Gaussian of DESIGN §1 integrated over the plane across it) and slabFractions.
//
// Along a pixel ray the kernel at distance ρ from the ray is the 1-D Gaussian truncated at
// ±√(R² − ρ²), centred at the ray's closest approach to the kernel centre, whose distance from
// the eye is √(D² − ρ²) = D − ρ²/2D + …; radial slabs are intervals of that distance. One set of
// fractions per primitive takes the kernel's marginal along the view direction, centred at D: the
// footprint-weighted mean of the per-ray profiles (exact for the mass each slab receives summed over
// the footprint; per ray it differs at the truncation, docs/compositing.md states by how much).
//
// The marginal of the truncated kernel g (DESIGN §1, s = s_g, N its normalisation) along an axis:
//     p(t) = N · 2π s² · (exp(−t²/2s²) − exp(−R²/2s²)),   |t| < R
//     C(x) = ∫_{−R}^{x} p = N · 2π s² · [ s√(2π) (Φ(x/s) − Φ(−R/s)) − exp(−R²/2s²) (x + R) ]
// and C(R) = N · (2π s²)^{3/2} · P(χ₃ < R/s) = 1 (docs/kernel.md §1): the fractions sum to 1
// before the renormalisation that makes them sum to 1 in float as well (the energy rule, DESIGN §4).
#pragma once
#include <array>

#include "footprint/kernel.h"

namespace vdbsplat {

/// The most slabs a primitive reaches on either side of its own (a window of 2K + 1 slabs).
inline constexpr int kMaxSlabReach = 4;
inline constexpr int kMaxSlabSpan = 2 * kMaxSlabReach + 1;

/// @brief The fractions of a primitive's optical depth for the slabs s − K + j, j = 0 … 2K
/// (K = the compositor's reach, at most kMaxSlabReach; the rest are 0). They sum to 1.
struct SlabProfile {
    std::array<float, kMaxSlabSpan> fraction{};
};

/// @brief The slab sums of one tile a primitive deposits into (--compositing slabs), each with the
/// fraction of the primitive's optical depth it takes: per pixel, slab j's τ += fraction[j]·τ and its
/// emission += fraction[j]·τ·colour. Arrays as the tile's (row-major, stride kTileSize, 64-byte aligned).
struct SlabTargets {
    int count = 0;
    std::array<float*, kMaxSlabSpan> tau{}, er{}, eg{}, eb{};
    std::array<float, kMaxSlabSpan> fraction{};
};

/// @brief C(@p x): the mass of @p kernel's marginal below @p x (kernel units: voxels); 0 below
/// −R, 1 above R.
double kernelMarginalCdf(const KernelShape& kernel, double x);

/// @brief C(x) of one kernel tabulated on [−R, R] (4096 intervals, linear): what the projection
/// evaluates per primitive. Measured max error against kernelMarginalCdf: 7e−8 (tested).
class MarginalCdfTable {
public:
    explicit MarginalCdfTable(const KernelShape& kernel);
    double operator()(double x) const {
        const double u = (x + radius_) * scale_;
        // Without branches (which tail a slab boundary falls in changes from primitive to
        // primitive): u ≤ 0 (or NaN) reads interval 0 at t = 0, i.e. C(−R) = 0 exactly, and
        // u ≥ kIntervals is replaced by 1 at the end.
        const double v = u > 0.0 && u < double(kIntervals) ? u : 0.0;
        const int i = int(v);
        const double t = v - double(i);
        const double c = value_[size_t(i)] + t * (value_[size_t(i) + 1] - value_[size_t(i)]);
        return u >= double(kIntervals) ? 1.0 : c;
    }
    static constexpr int kIntervals = 4096;
    /// The table as the vector fractions read it (slabFractionsBatch): C at the kIntervals + 1
    /// points −R + i / scale().
    double radius() const { return radius_; }
    double scale() const { return scale_; }
    const double* values() const { return value_.data(); }

private:
    double radius_, scale_;
    std::array<double, kIntervals + 1> value_;
};

/// @brief The slab fractions of a kernel centred at @p offset slab lengths past the start of its
/// own slab s (normally in [0, 1)), whose kernel unit measures @p unitInSlabs slab lengths along
/// the view ray (h / slab length for a sphere; larger for an elongated or aggregated kernel),
/// over the slabs s − @p reach … s + @p reach and, of those, only the ones at or past relative
/// slab @p lowest (slabs before the eye: −s). Mass beyond the slabs reached is left out and
/// the rest renormalised to sum to 1 (the truncation of a wide aggregate's profile).
/// C(x) is kernelMarginalCdf, or the MarginalCdfTable of it (the projection's).
SlabProfile slabFractions(const KernelShape& kernel, double offset, double unitInSlabs, int reach, int lowest = -kMaxSlabReach);
SlabProfile slabFractions(const MarginalCdfTable& cdf, double offset, double unitInSlabs, int reach, int lowest = -kMaxSlabReach);

/// @brief What slabFractions(@p cdf, offset[k], unitInSlabs[k], @p reach, lowest[k]) gives, for
/// k < @p n, into @p out[k]: bit for bit (the same double operations in the same order, a vector
/// of primitives at a time with Google Highway; composite/slab_fractions.cpp).
void slabFractionsBatch(const MarginalCdfTable& cdf, const double* offset, const double* unitInSlabs, const int* lowest,
                        size_t n, int reach, SlabProfile* out);

/// @brief The reach K (slabs on either side) a kernel of radius @p radiusInSlabs slab lengths
/// needs, at most kMaxSlabReach: ⌈R⌉ (a centre anywhere in its slab).
int slabReachFor(double radiusInSlabs);

}  // namespace vdbsplat
