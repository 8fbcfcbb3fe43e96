// tests/footprint/kernel_shape_test.cpp — the reconstruction kernels of --kernel (footprint/kernel.h
// KernelShape, docs/kernel.md §10): each one normalised to a unit volume integral, its closed-form
// footprint against a numeric line integral of the kernel itself, its table against the closed
// form with the error its header states, and the sharper kernel really sharper.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "footprint/footprint_poly.h"
#include "footprint/kernel.h"
#include "footprint/tables.h"
#include "util/error.h"

namespace vdbsplat {
namespace {

const KernelShape* const kKernels[] = {&KernelShape::standard(), &KernelShape::sharp()};

TEST(KernelShape, EachHasUnitVolumeIntegral) {
    for (const KernelShape* k : kKernels) {
        const double v = k->volumeIntegral(200);  // midpoint rule on 200³ cells
        std::printf("  %-15s ∫g dV = %.6f, ∫∫F dA = %.8f\n", k->id(), v, k->footprintPlaneIntegral());
        EXPECT_NEAR(v, 1.0, 2e-3) << k->id();
        EXPECT_NEAR(k->footprintPlaneIntegral(), 1.0, 1e-6) << k->id();
    }
}

// F(ρ) (erf closed form) against the midpoint rule on g itself along the chord (the chord's ends
// are the truncation's step, so no rule that samples them).
TEST(KernelShape, FootprintIsTheLineIntegralOfTheKernel) {
    for (const KernelShape* k : kKernels)
        for (const double rho : {0.0, 0.3, 0.8, 1.2, 1.5, 1.54, 1.9}) {
            const double R = k->radius();
            double numeric = 0.0;
            if (rho < R) {
                const double half = std::sqrt(R * R - rho * rho);
                const int n = 20000;
                const double h = 2.0 * half / n;
                for (int i = 0; i < n; ++i) {
                    const double t = -half + (i + 0.5) * h;
                    numeric += k->value(rho * rho + t * t) * h;
                }
            }
            EXPECT_NEAR(k->footprint(rho), numeric, 1e-8) << k->id() << " ρ " << rho;
        }
    EXPECT_EQ(KernelShape::sharp().footprint(1.56), 0.0);  // beyond its R = 1.55
    EXPECT_GT(KernelShape::standard().footprint(1.56), 0.0);
}

/// ∫∫ F(|x|) cos(2π ν x) dA: the kernel's frequency response at ν cycles per voxel.
double response(const KernelShape& k, double nu) {
    const int n = 400;
    const double R = k.radius(), h = 2.0 * R / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double x = -R + (i + 0.5) * h, y = -R + (j + 0.5) * h;
            sum += k.footprint(std::hypot(x, y)) * std::cos(2.0 * std::numbers::pi * nu * x);
        }
    return sum * h * h;
}

// The point of the sharper kernel: more response at the grid's Nyquist frequency (½ cycle per
// voxel) than the standard Gaussian's 0.12 (docs/kernel.md §1), closer to trilinear's 0.41.
TEST(KernelShape, SharpKernelPassesMoreOfTheNyquistFrequency) {
    const double standard = response(KernelShape::standard(), 0.5), sharp = response(KernelShape::sharp(), 0.5);
    std::printf("  response at Nyquist: gaussian %.4f, gaussian-sharp %.4f (trilinear %.4f)\n", standard, sharp,
                std::pow(2.0 / std::numbers::pi, 2.0));
    EXPECT_NEAR(standard, 0.124, 0.01);
    EXPECT_GT(sharp, 2.0 * standard);
    EXPECT_LT(sharp, std::pow(2.0 / std::numbers::pi, 2.0));
}

std::string readAll(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Each kernel's shipped table (tables/, written by `vdbsplat tables`) names its kernel, states a
// bound, and is within it of the closed form; a table of one kernel is refused for the other.
TEST(KernelShape, TablePerKernelWithinItsStatedError) {
    for (const KernelShape* k : kKernels) {
        const std::filesystem::path path = defaultTablesDir() / footprintTableFile(*k);
        const std::string bytes = readAll(path);
        ASSERT_FALSE(bytes.empty()) << path;
        EXPECT_NE(bytes.find(std::string("kernel ") + k->tableName() + "\n"), std::string::npos) << path;
        const FootprintTable t = parseFootprintTable(bytes, path.string(), *k);
        const double measured = measureFootprintError(t, *k);
        std::printf("  %-15s table max error %.3e, header bound %.2e\n", k->id(), measured, t.errorBound());
        EXPECT_LE(measured, t.errorBound()) << k->id();
        EXPECT_LT(t.errorBound(), 1e-3 * k->footprint(0.0)) << k->id();
        EXPECT_NEAR(t.lookupD2(0.25f), k->footprint(0.5 * k->radius()), t.errorBound());
        const KernelShape& other = k == kKernels[0] ? KernelShape::sharp() : KernelShape::standard();
        EXPECT_THROW(parseFootprintTable(bytes, path.string(), other), Error) << k->id();
        const Tables loaded = loadOrBuildTables(defaultTablesDir(), *k);
        EXPECT_EQ(loaded.kernel, k);
        EXPECT_EQ(loaded.footprint.values(), t.values());
    }
}

TEST(KernelShape, VectorLoopPolynomialsFitEachKernel) {
    for (const KernelShape* k : kKernels) {
        const double err = FootprintPolynomials::build(*k).measureError(*k);
        std::printf("  %-15s polynomial max error %.2e of F(0)\n", k->id(), err);
        EXPECT_LT(err, FootprintPolynomials::kErrorBound) << k->id();
    }
    // Fitted to the wrong kernel, it is far off: the fit follows the kernel.
    EXPECT_GT(FootprintPolynomials::build(KernelShape::standard()).measureError(KernelShape::sharp()), 0.1);
}

TEST(KernelShape, UnknownNameIsAnErrorNamingTheFlag) {
    EXPECT_EQ(&KernelShape::named("gaussian"), &KernelShape::standard());
    EXPECT_EQ(&KernelShape::named("gaussian-sharp"), &KernelShape::sharp());
    try {
        KernelShape::named("bspline");
        FAIL() << "no throw";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "--kernel: unknown kernel 'bspline' (choose gaussian, gaussian-sharp)");
    }
}

}  // namespace
}  // namespace vdbsplat
