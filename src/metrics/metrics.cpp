// metrics/metrics.cpp — MSE/RMSE/PSNR/max error and SSIM on sRGB display values.
// Owns: the definitions documented in metrics.h (Wang et al. 2004 for SSIM).
#include "metrics/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "util/error.h"

namespace vdbsplat {

namespace {

// SSIM constants (Wang, Bovik, Sheikh, Simoncelli 2004): K1 = 0.01, K2 = 0.03, L = 1.
constexpr double kC1 = 0.01 * 0.01;
constexpr double kC2 = 0.03 * 0.03;
constexpr int kWindowRadius = 5;      // 11×11 window
constexpr double kWindowSigma = 1.5;  // Gaussian σ in pixels


bool hasNan(const glm::vec4& p) { return std::isnan(p.x) || std::isnan(p.y) || std::isnan(p.z); }

void checkSizes(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height)
        throw Error("image sizes differ: " + sizeText(a) + " vs " + sizeText(b));
    if (a.width < 1 || a.height < 1) throw Error("cannot compare empty images (" + sizeText(a) + ")");
}

/// Display luma Y' of every pixel.
std::vector<double> luma(const Image& image) {
    std::vector<double> y(image.pixels.size());
    for (size_t i = 0; i < y.size(); ++i) {
        const glm::vec4& p = image.pixels[i];
        y[i] = 0.2126 * displayValue(p.x) + 0.7152 * displayValue(p.y) + 0.0722 * displayValue(p.z);
    }
    return y;
}

std::array<double, 2 * kWindowRadius + 1> gaussianTaps() {
    std::array<double, 2 * kWindowRadius + 1> w{};
    for (int k = -kWindowRadius; k <= kWindowRadius; ++k)
        w[size_t(k + kWindowRadius)] = std::exp(-0.5 * k * k / (kWindowSigma * kWindowSigma));
    return w;
}

/// Separable Gaussian blur; taps outside the image are dropped and the rest renormalised.
std::vector<double> blur(const std::vector<double>& in, int width, int height) {
    static const auto taps = gaussianTaps();
    std::vector<double> tmp(in.size()), out(in.size());
    auto pass = [&](const std::vector<double>& src, std::vector<double>& dst, bool horizontal) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                double sum = 0.0, weight = 0.0;
                for (int k = -kWindowRadius; k <= kWindowRadius; ++k) {
                    const int sx = horizontal ? x + k : x, sy = horizontal ? y : y + k;
                    if (sx < 0 || sx >= width || sy < 0 || sy >= height) continue;
                    const double w = taps[size_t(k + kWindowRadius)];
                    sum += w * src[size_t(sy) * width + sx];
                    weight += w;
                }
                dst[size_t(y) * width + x] = sum / weight;
            }
    };
    pass(in, tmp, true);
    pass(tmp, out, false);
    return out;
}

std::vector<double> product(const std::vector<double>& a, const std::vector<double>& b) {
    std::vector<double> p(a.size());
    for (size_t i = 0; i < a.size(); ++i) p[i] = a[i] * b[i];
    return p;
}

}  // namespace

double displayValue(float linear) {
    const double v = double(linear);
    if (std::isnan(v) || v <= 0.0) return 0.0;
    if (v >= 1.0) return 1.0;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

std::string sizeText(const Image& image) { return std::to_string(image.width) + "x" + std::to_string(image.height); }

double psnrFromMse(double mse) {
    if (mse <= 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(1.0 / mse);
}

double ssim(const Image& image, const Image& reference) {
    checkSizes(image, reference);
    const int w = image.width, h = image.height;
    const std::vector<double> x = luma(image), y = luma(reference);
    const auto mx = blur(x, w, h), my = blur(y, w, h);
    const auto exx = blur(product(x, x), w, h), eyy = blur(product(y, y), w, h), exy = blur(product(x, y), w, h);
    double sum = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double vx = exx[i] - mx[i] * mx[i], vy = eyy[i] - my[i] * my[i], cxy = exy[i] - mx[i] * my[i];
        sum += ((2.0 * mx[i] * my[i] + kC1) * (2.0 * cxy + kC2)) /
               ((mx[i] * mx[i] + my[i] * my[i] + kC1) * (vx + vy + kC2));
    }
    return sum / double(x.size());
}

ImageMetrics compareImages(const Image& image, const Image& reference) {
    checkSizes(image, reference);
    ImageMetrics m;
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y) {
        double row = 0.0;  // per-row partial sums keep rounding small on large images
        for (int x = 0; x < image.width; ++x) {
            const glm::vec4& a = image.at(x, y);
            const glm::vec4& b = reference.at(x, y);
            if (hasNan(a) || hasNan(b)) ++m.nonFinitePixels;
            for (int c = 0; c < 3; ++c) {
                const double d = displayValue(a[c]) - displayValue(b[c]);
                row += d * d;
                m.maxAbsError = std::max(m.maxAbsError, std::abs(d));
            }
        }
        sum += row;
    }
    m.mse = sum / (3.0 * double(image.pixels.size()));
    m.rmse = std::sqrt(m.mse);
    m.psnr = psnrFromMse(m.mse);
    m.ssim = ssim(image, reference);
    return m;
}

}  // namespace vdbsplat
