// footprint/footprint_poly.h — the splat footprint F(d(i, α)) as one polynomial per splat.
// Owns: FootprintPolynomials, the vector loop's replacement for the two dependent table
// lookups of the (i, α) path (i² → reindex row → footprint table), and its error bound.
//
// The maths (DESIGN §3, kernel.h): with t = i² and d² = t / (cos²α + t·sin²α) (the corrected
// reindex), the truncated Gaussian's footprint is
//     F = N·s_g·√(π/2)·exp(−R²d²/2s_g²) · 2·erf(R·√(1−d²)/(√2·s_g)),
// and since erf(b√u)/√u is an entire function of u and 1 − d² = cos²α·(1 − t)/(cos²α + t·sin²α),
//     F(t, α) = √(1 − t) · G_α(t)     with G_α analytic on [0, 1] for α ≤ 15°.
// G_α is fitted by a degree-8 polynomial in x = 2t − 1 (interpolation at Chebyshev nodes,
// Σ|c_k| ≈ G(0), so float Horner loses nothing to cancellation) on 33 rows uniform in sin²α
// ∈ [0, sin²15°]; a splat interpolates its coefficients linearly between two rows once, and
// every pixel then costs √(1 − t) and 8 FMAs, vectorisable, no gathers. (Degree 10 erred 5e−7
// for two FMAs more; degree 8's 6e−6 is still 5× below the footprint table's 3e−5.)
// The α = 0 row is F as a function of d² itself: the exact-index path uses it.
// Measured bound (FootprintPoly tests): |F_poly − F| ≤ kErrorBound·F(0), evaluated in float.
#pragma once
#include <algorithm>
#include <array>
#include <vector>

#include "footprint/kernel.h"

namespace vdbsplat {

class FootprintPolynomials {
public:
    static constexpr int kDegree = 8;
    static constexpr int kCoefficients = kDegree + 1;
    static constexpr int kRows = 32;                ///< intervals in sin²α
    static constexpr double kAlphaMaxDeg = 15.0;    ///< beyond: the table path (closed-form reindex)
    static constexpr double kErrorBound = 1.0e-5;   ///< relative to F(0); measured ≈ 6.3e−6

    static constexpr int kStorage = 12;              ///< kCoefficients and zeros: row()'s lerp vectorises
    using Coefficients = std::array<float, kStorage>;  ///< c_0 … c_8 in x = 2t − 1, then zeros

    /// @brief Fits every row from Kernel::footprint (deterministic, in memory, well under 1 ms).
    static FootprintPolynomials build(const KernelShape& kernel = KernelShape::standard());

    /// @brief True when a splat of half cone angle with sin²α = @p sin2Alpha is covered.
    bool covers(double sin2Alpha) const { return sin2Alpha >= 0.0 && sin2Alpha <= sin2Max_; }
    /// @brief The coefficients for sin²α = @p sin2Alpha (must be covered): rows interpolated linearly.
    Coefficients row(double sin2Alpha) const {  // inline: the splat loop's caller keeps it in registers
        // × the stored kRows / sin²α_max, not ÷ sin²α_max: a division's latency began every splat's
        // draw (the product can differ from the quotient in its last bit, a weight's in 2^−29).
        const double pos = std::clamp(sin2Alpha * rowsPerSin2_, 0.0, double(kRows));
        const int k = std::min(int(pos), kRows - 1);
        const float w = float(pos - k);
        const Coefficients &a = rows_[size_t(k)], &b = rows_[size_t(k) + 1];
        Coefficients c;
        for (int j = 0; j < kStorage; ++j) c[size_t(j)] = a[size_t(j)] + w * (b[size_t(j)] - a[size_t(j)]);
        return c;
    }
    /// @brief The α = 0 row: F as a polynomial in d² (for the exact-index path).
    const Coefficients& axisRow() const { return rows_.front(); }

    /// @brief √(1 − t)·Σ c_k (2t − 1)^k in float, as the vector loop computes it; 0 for t ≥ 1.
    static float evaluate(const Coefficients& c, float t);

    double sin2Max() const { return sin2Max_; }
    /// @brief An upper bound on evaluate() over every row and t (F(0) and a margin): a splat's τ
    /// is at most its scale times this (SplatRaster::series).
    float peak() const { return peak_; }
    /// @brief Max |evaluate − Kernel::footprint| / F(0) over a dense sampling of t and α.
    double measureError(const KernelShape& kernel = KernelShape::standard()) const;

private:
    std::vector<Coefficients> rows_;  // kRows + 1
    double sin2Max_ = 0.0;
    double rowsPerSin2_ = 0.0;  ///< kRows / sin2Max_
    float peak_ = 0.f;
};

}  // namespace vdbsplat
