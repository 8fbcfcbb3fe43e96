// footprint/footprint_poly.cpp — per-α polynomial fits of the splat footprint (see footprint_poly.h).
#include "footprint/footprint_poly.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "footprint/kernel.h"

namespace vdbsplat {

namespace {

/// d² of the corrected reindex (DESIGN §3) at t = i², for sin²α = @p s2.
double reindexD2(double t, double s2) { return t / ((1.0 - s2) + t * s2); }

/// G_α(t) = F(d(t)) / √(1 − t), t < 1 (voxel units, as the footprint table).
double g(double t, double s2, const KernelShape& kernel) {
    const double d2 = reindexD2(t, s2);
    return kernel.footprint(kernel.radius() * std::sqrt(std::max(d2, 0.0))) / std::sqrt(1.0 - t);
}

/// Solves the (n × n) system A·c = y by Gaussian elimination with partial pivoting.
std::vector<double> solve(std::vector<std::vector<double>> a, std::vector<double> y) {
    const size_t n = y.size();
    for (size_t col = 0; col < n; ++col) {
        size_t pivot = col;
        for (size_t r = col + 1; r < n; ++r)
            if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
        std::swap(a[col], a[pivot]);
        std::swap(y[col], y[pivot]);
        for (size_t r = col + 1; r < n; ++r) {
            const double f = a[r][col] / a[col][col];
            for (size_t k = col; k < n; ++k) a[r][k] -= f * a[col][k];
            y[r] -= f * y[col];
        }
    }
    std::vector<double> c(n);
    for (size_t i = n; i-- > 0;) {
        double s = y[i];
        for (size_t k = i + 1; k < n; ++k) s -= a[i][k] * c[k];
        c[i] = s / a[i][i];
    }
    return c;
}

/// Interpolates G_α at the Chebyshev nodes of x = 2t − 1 ∈ (−1, 1): monomial coefficients in x.
FootprintPolynomials::Coefficients fitRow(double s2, const KernelShape& kernel) {
    constexpr int n = FootprintPolynomials::kCoefficients;
    std::vector<std::vector<double>> vandermonde(n, std::vector<double>(n));
    std::vector<double> values(n);
    for (int k = 0; k < n; ++k) {
        const double x = std::cos(std::numbers::pi * (k + 0.5) / n);
        double p = 1.0;
        for (int j = 0; j < n; ++j, p *= x) vandermonde[size_t(k)][size_t(j)] = p;
        values[size_t(k)] = g(0.5 * (x + 1.0), s2, kernel);
    }
    const std::vector<double> c = solve(std::move(vandermonde), std::move(values));
    FootprintPolynomials::Coefficients out{};
    for (int j = 0; j < n; ++j) out[size_t(j)] = float(c[size_t(j)]);
    return out;
}

}  // namespace

FootprintPolynomials FootprintPolynomials::build(const KernelShape& kernel) {
    FootprintPolynomials p;
    const double s = std::sin(kAlphaMaxDeg * std::numbers::pi / 180.0);
    p.sin2Max_ = s * s;
    p.rowsPerSin2_ = kRows / p.sin2Max_;
    p.rows_.reserve(kRows + 1);
    for (int r = 0; r <= kRows; ++r) p.rows_.push_back(fitRow(p.sin2Max_ * r / kRows, kernel));
    // The largest value any row takes (a splat's row is a convex combination of two): F falls with
    // t, so a row's largest is its value at t = 0 up to the fit's error (kErrorBound·F(0)), which
    // the margin covers 100 times over (FootprintPoly.PeakBoundsEveryRow samples it densely).
    float peak = 0.f;
    for (const Coefficients& c : p.rows_) peak = std::max(peak, evaluate(c, 0.f));
    p.peak_ = peak * 1.001f;
    return p;
}

float FootprintPolynomials::evaluate(const Coefficients& c, float t) {
    if (!(t < 1.0f)) return 0.0f;
    t = std::max(t, 0.0f);
    const float x = 2.0f * t - 1.0f;
    float p = c[kDegree];
    for (int j = kDegree - 1; j >= 0; --j) p = p * x + c[size_t(j)];
    return std::max(std::sqrt(1.0f - t) * p, 0.0f);
}

double FootprintPolynomials::measureError(const KernelShape& kernel) const {
    const double f0 = kernel.footprint(0.0);
    double worst = 0.0;
    constexpr int kAlphas = 4 * kRows, kTs = 2000;
    for (int a = 0; a <= kAlphas; ++a) {
        const double s2 = sin2Max_ * a / kAlphas;
        const Coefficients c = row(s2);
        for (int i = 0; i < kTs; ++i) {
            const double t = double(i) / kTs;
            const double exact = kernel.footprint(kernel.radius() * std::sqrt(reindexD2(t, s2)));
            worst = std::max(worst, std::abs(double(evaluate(c, float(t))) - exact) / f0);
        }
    }
    return worst;
}

}  // namespace vdbsplat
