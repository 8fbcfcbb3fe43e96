// study/error_map.cpp — error heat maps, their colour ramp and the crop window (see error_map.h).
#include "study/error_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "metrics/metrics.h"
#include "util/error.h"

namespace vdbsplat::study {

namespace {

/// Viridis at 9 even stops (matplotlib's table, sampled): dark violet → blue → green → yellow.
constexpr double kRamp[9][3] = {{0.267, 0.005, 0.329}, {0.278, 0.175, 0.483}, {0.231, 0.322, 0.546},
                                {0.173, 0.449, 0.558}, {0.128, 0.567, 0.551}, {0.153, 0.683, 0.502},
                                {0.369, 0.789, 0.383}, {0.678, 0.864, 0.190}, {0.993, 0.906, 0.144}};

}  // namespace

double heatPosition(double e) {
    if (std::isnan(e)) return 1.0;
    if (e <= kHeatLow) return 0.0;
    if (e >= kHeatHigh) return 1.0;
    return std::log(e / kHeatLow) / std::log(kHeatHigh / kHeatLow);
}

glm::dvec3 heatColour(double t) {
    t = std::clamp(std::isnan(t) ? 1.0 : t, 0.0, 1.0) * 8.0;
    const int i = std::min(7, int(t));
    const double f = t - double(i);
    glm::dvec3 c;
    for (int k = 0; k < 3; ++k) c[k] = kRamp[i][k] + f * (kRamp[i + 1][k] - kRamp[i][k]);
    return c;
}

std::string heatHex(double t) {
    const glm::dvec3 c = heatColour(t);
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", int(std::lround(c.x * 255)), int(std::lround(c.y * 255)),
                  int(std::lround(c.z * 255)));
    return buf;
}

std::vector<double> pixelErrors(const Image& image, const Image& reference) {
    if (image.width != reference.width || image.height != reference.height || image.pixels.empty())
        throw Error("image sizes differ: " + sizeText(image) + " vs " + sizeText(reference));
    std::vector<double> e(image.pixels.size());
    for (size_t i = 0; i < e.size(); ++i) {
        double sum = 0.0;
        for (int c = 0; c < 3; ++c)
            sum += std::abs(displayValue(image.pixels[i][c]) - displayValue(reference.pixels[i][c]));
        e[i] = sum / 3.0;
    }
    return e;
}

Image heatMap(const std::vector<double>& errors, int width, int height) {
    Image im(width, height);
    for (size_t i = 0; i < im.pixels.size() && i < errors.size(); ++i) {
        const glm::dvec3 c = heatColour(heatPosition(errors[i]));
        // writeImage encodes linear values to sRGB: hand it the ramp's display colour decoded.
        im.pixels[i] = glm::vec4(srgbToLinear(float(c.x)), srgbToLinear(float(c.y)), srgbToLinear(float(c.z)), 1.0f);
    }
    return im;
}

int cropSide(int width, int height) {
    const int shorter = std::min(width, height);
    return std::min(shorter, std::max(8, shorter / 4));
}

CropWindow worstWindow(const std::vector<std::vector<double>>& errors, int width, int height) {
    const int side = cropSide(width, height), step = std::max(1, side / 2);
    // Summed-area table of the errors of every mode.
    const size_t W = size_t(width) + 1;
    std::vector<double> sat(W * (size_t(height) + 1), 0.0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double v = 0.0;
            for (const auto& e : errors)
                if (e.size() == size_t(width) * size_t(height) && std::isfinite(e[size_t(y) * width + x]))
                    v += e[size_t(y) * width + x];
            sat[(y + 1) * W + x + 1] = v + sat[y * W + x + 1] + sat[(y + 1) * W + x] - sat[y * W + x];
        }
    CropWindow best{(width - side) / 2, (height - side) / 2, side};
    double bestSum = 0.0;
    for (int y = 0; y + side <= height; y += step)
        for (int x = 0; x + side <= width; x += step) {
            const double s = sat[(y + side) * W + x + side] - sat[y * W + x + side] - sat[(y + side) * W + x] + sat[y * W + x];
            if (s > bestSum) bestSum = s, best = {x, y, side};
        }
    return best;
}

Image crop(const Image& image, const CropWindow& w) {
    if (w.size < 1 || w.x < 0 || w.y < 0 || w.x + w.size > image.width || w.y + w.size > image.height)
        throw Error("crop window outside the " + sizeText(image) + " image");
    Image out(w.size, w.size);
    for (int y = 0; y < w.size; ++y)
        for (int x = 0; x < w.size; ++x) out.at(x, y) = image.at(w.x + x, w.y + y);
    return out;
}

}  // namespace vdbsplat::study
