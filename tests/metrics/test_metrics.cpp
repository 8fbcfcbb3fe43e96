// tests/metrics/test_metrics.cpp — image metrics: PSNR/MSE on sRGB display values
// (closed forms for uniform offsets), identical images, symmetry, SSIM, sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "image/image.h"
#include "metrics/metrics.h"
#include "util/error.h"

namespace vdbsplat {
namespace {

Image uniform(int w, int h, glm::vec4 value) {
    Image img(w, h);
    for (auto& p : img.pixels) p = value;
    return img;
}

/// A smooth colourful test pattern (linear premultiplied RGB, alpha 1).
Image pattern(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.at(x, y) = glm::vec4(0.5f + 0.4f * std::sin(0.3f * x), 0.5f + 0.4f * std::cos(0.2f * y),
                                     float(x + y) / float(w + h), 1.f);
    return img;
}

Image withNoise(const Image& src, float amplitude, unsigned seed) {
    Image img = src;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-amplitude, amplitude);
    for (auto& p : img.pixels)
        for (int c = 0; c < 3; ++c) p[c] = std::clamp(p[c] + u(rng), 0.f, 1.f);
    return img;
}

TEST(Metrics, IdenticalImagesAreInfinitePsnrAndUnitSsim) {
    const Image a = pattern(37, 23);
    const ImageMetrics m = compareImages(a, a);
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.maxAbsError, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
    EXPECT_DOUBLE_EQ(m.ssim, 1.0);
    EXPECT_EQ(m.nonFinitePixels, 0u);
}

TEST(Metrics, UniformOffsetMatchesClosedForm) {
    // Display values: black vs sRGB(v) in every channel → MSE = sRGB(v)², PSNR = 10·log10(1/MSE).
    for (float v : {0.001f, 0.05f, 0.2f, 0.5f}) {
        const Image black = uniform(16, 9, glm::vec4(0.f, 0.f, 0.f, 1.f));
        const Image grey = uniform(16, 9, glm::vec4(v, v, v, 1.f));
        const double d = displayValue(v);
        const ImageMetrics m = compareImages(grey, black);
        EXPECT_NEAR(m.mse, d * d, 1e-13 * d * d) << v;
        EXPECT_NEAR(m.rmse, d, 1e-13 * d) << v;
        EXPECT_EQ(m.maxAbsError, d) << v;
        EXPECT_EQ(m.psnr, 10.0 * std::log10(1.0 / m.mse)) << v;  // the definition, exactly
        EXPECT_NEAR(m.psnr, -20.0 * std::log10(d), 1e-10) << v;   // and the closed form
    }
    // Full-scale difference: MSE = 1, PSNR = 0 dB.
    const ImageMetrics full = compareImages(uniform(4, 4, glm::vec4(1.f)), uniform(4, 4, glm::vec4(0.f)));
    EXPECT_DOUBLE_EQ(full.mse, 1.0);
    EXPECT_DOUBLE_EQ(full.psnr, 0.0);
    // One channel of one pixel off by sRGB 1: MSE = 1 / (3·N).
    Image one = uniform(10, 10, glm::vec4(0.f));
    one.at(3, 4).y = 1.f;
    const ImageMetrics m1 = compareImages(one, uniform(10, 10, glm::vec4(0.f)));
    EXPECT_DOUBLE_EQ(m1.mse, 1.0 / 300.0);
    EXPECT_NEAR(m1.psnr, 10.0 * std::log10(300.0), 1e-12);
}

TEST(Metrics, ComparesDisplayValuesOverBlack) {
    // Values above 1 clamp like the PNG does; alpha does not matter (premultiplied over black).
    const ImageMetrics hdr = compareImages(uniform(3, 3, glm::vec4(5.f, 5.f, 5.f, 1.f)), uniform(3, 3, glm::vec4(1.f)));
    EXPECT_EQ(hdr.mse, 0.0);
    const ImageMetrics alpha =
        compareImages(uniform(3, 3, glm::vec4(0.2f, 0.3f, 0.4f, 0.1f)), uniform(3, 3, glm::vec4(0.2f, 0.3f, 0.4f, 1.f)));
    EXPECT_EQ(alpha.mse, 0.0);
    // A linear difference of 0.01 near black is far bigger on the display than near white.
    const double dark = compareImages(uniform(2, 2, glm::vec4(0.02f)), uniform(2, 2, glm::vec4(0.01f))).rmse;
    const double bright = compareImages(uniform(2, 2, glm::vec4(0.99f)), uniform(2, 2, glm::vec4(0.98f))).rmse;
    EXPECT_GT(dark, 5.0 * bright);
}

TEST(Metrics, Symmetric) {
    const Image a = pattern(40, 30), b = withNoise(a, 0.1f, 3);
    const ImageMetrics ab = compareImages(a, b), ba = compareImages(b, a);
    EXPECT_DOUBLE_EQ(ab.mse, ba.mse);
    EXPECT_DOUBLE_EQ(ab.psnr, ba.psnr);
    EXPECT_DOUBLE_EQ(ab.maxAbsError, ba.maxAbsError);
    EXPECT_NEAR(ab.ssim, ba.ssim, 1e-12);
}

TEST(Metrics, SsimFallsWithNoise) {
    const Image a = pattern(64, 48);
    const double mild = ssim(withNoise(a, 0.02f, 1), a);
    const double strong = ssim(withNoise(a, 0.2f, 1), a);
    EXPECT_LT(mild, 1.0);
    EXPECT_GT(mild, 0.5);
    EXPECT_LT(strong, mild);
    EXPECT_GT(strong, -1.0);
}

TEST(Metrics, SsimOfFlatImagesIsTheLuminanceTerm) {
    // No variance anywhere: SSIM = (2·μx·μy + C1) / (μx² + μy² + C1) with display luma μ.
    const float vx = 0.2f, vy = 0.6f;
    const double mx = displayValue(vx), my = displayValue(vy), c1 = 1e-4;
    const double expected = (2 * mx * my + c1) / (mx * mx + my * my + c1);
    EXPECT_NEAR(ssim(uniform(20, 20, glm::vec4(vx, vx, vx, 1)), uniform(20, 20, glm::vec4(vy, vy, vy, 1))), expected,
                1e-9);
}

TEST(Metrics, TinyImagesWork) {
    const Image a = pattern(3, 2);
    EXPECT_DOUBLE_EQ(ssim(a, a), 1.0);
    EXPECT_LT(ssim(withNoise(a, 0.3f, 9), a), 1.0);
}

TEST(Metrics, SizeMismatchThrows) {
    try {
        compareImages(Image(4, 4), Image(5, 4));
        FAIL() << "expected Error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "image sizes differ: 4x4 vs 5x4");
    }
    EXPECT_THROW(ssim(Image(4, 4), Image(4, 5)), Error);
    EXPECT_THROW(compareImages(Image(), Image()), Error);
}

TEST(Metrics, NanPixelsAreCountedAndComparedAsBlack) {
    Image a = uniform(4, 4, glm::vec4(0.f));
    a.at(1, 1).x = NAN;
    const ImageMetrics m = compareImages(a, uniform(4, 4, glm::vec4(0.f)));
    EXPECT_EQ(m.nonFinitePixels, 1u);
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_FALSE(std::isnan(m.ssim));
}

TEST(Metrics, DisplayValueIsTheSrgbCurve) {
    EXPECT_EQ(displayValue(0.f), 0.0);
    EXPECT_EQ(displayValue(1.f), 1.0);
    EXPECT_EQ(displayValue(-2.f), 0.0);
    EXPECT_EQ(displayValue(INFINITY), 1.0);
    EXPECT_EQ(displayValue(NAN), 0.0);
    for (float v = 0.f; v <= 1.f; v += 1.f / 256)
        EXPECT_NEAR(displayValue(v), linearToSrgb(v), 1e-6) << v;  // the PNG encoder's curve
    EXPECT_NEAR(displayValue(0.5f), 0.735356983, 1e-8);
}

TEST(Metrics, PsnrFromMse) {
    EXPECT_TRUE(std::isinf(psnrFromMse(0.0)));
    EXPECT_DOUBLE_EQ(psnrFromMse(0.01), 20.0);
    EXPECT_DOUBLE_EQ(psnrFromMse(1e-4), 40.0);
}

}  // namespace
}  // namespace vdbsplat
