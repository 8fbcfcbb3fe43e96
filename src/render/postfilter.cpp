// render/postfilter.cpp — sub-pixel grid and the image-space prefilter (see postfilter.h).
#include "render/postfilter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "footprint/prefilter.h"
#include "util/error.h"

namespace vdbsplat {

SubpixelGrid makeSubpixelGrid(int k, double prefilterVariance) {
    if (k < 1) throw Error("--subpixels: must be at least 1");
    SubpixelGrid g;
    g.k = k;
    // V_s/k² may not exceed V_h: keep at least a quarter of the low-pass for the image.
    g.fineVariance = std::min(kSubpixelPrefilterVariance, 0.75 * prefilterVariance * k * k);
    g.postVariance = prefilterVariance - g.fineVariance / (double(k) * k);
    g.border = int(std::ceil(kPrefilterCutoffSigmas * std::sqrt(g.postVariance)));
    return g;
}

Camera subpixelCamera(const Camera& camera, const SubpixelGrid& grid) {
    const int W = camera.width() + 2 * grid.border, H = camera.height() + 2 * grid.border;
    // Same focal length per pixel: f = H/2 / tan(fov/2) with the larger H (camera.cpp), so
    // tan(fov'/2) = tan(fov/2)·H'/H.
    const double halfTan = std::tan(0.5 * camera.fovDeg() * std::numbers::pi / 180.0) * double(H) / camera.height();
    const double fov = 2.0 * std::atan(halfTan) * 180.0 / std::numbers::pi;
    return Camera(camera.eye(), camera.lookAt(), camera.up(), fov, grid.k * W, grid.k * H);
}

PostfilterTaps postfilterTaps(const SubpixelGrid& grid) {
    // Output pixel x has its centre at x + 0.5; sub-pixel k(x + border) + t has its centre at
    // x + (t + 0.5)/k, so the offset (t + 0.5 − k/2)/k does not depend on x.
    const double k = grid.k, reach = kPrefilterCutoffSigmas * std::sqrt(grid.postVariance);
    PostfilterTaps taps;
    taps.first = int(std::ceil(-reach * k + 0.5 * k - 0.5));
    const int last = int(std::floor(reach * k + 0.5 * k - 0.5));
    double sum = 0.0;
    std::vector<double> w;
    for (int t = taps.first; t <= last; ++t) {
        const double dx = (t + 0.5 - 0.5 * k) / k;
        w.push_back(grid.postVariance > 0.0 ? std::exp(-0.5 * dx * dx / grid.postVariance) : 1.0);
        sum += w.back();
    }
    for (double v : w) taps.weights.push_back(float(v / sum));
    return taps;
}

Image postfilterImage(const Image& fine, const SubpixelGrid& grid, int width, int height) {
    const PostfilterTaps taps = postfilterTaps(grid);
    const int k = grid.k, fw = fine.width, n = int(taps.weights.size());
    if (fw != k * (width + 2 * grid.border) || fine.height != k * (height + 2 * grid.border))
        throw Error("postfilter: the sub-pixel image does not match the grid");
    // Horizontal pass: every sub-pixel row, output columns.
    Image rows(width, fine.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, fine.height, 16), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y)
            for (int x = 0; x < width; ++x) {
                const int s0 = k * (x + grid.border) + taps.first;
                glm::vec4 sum(0.f);
                for (int j = 0; j < n; ++j) sum += taps.weights[size_t(j)] * fine.at(s0 + j, y);
                rows.at(x, y) = sum;
            }
    });
    // Vertical pass.
    Image out(width, height);
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) {
            const int s0 = k * (y + grid.border) + taps.first;
            for (int x = 0; x < width; ++x) {
                glm::vec4 sum(0.f);
                for (int j = 0; j < n; ++j) sum += taps.weights[size_t(j)] * rows.at(x, s0 + j);
                out.at(x, y) = sum;
            }
        }
    });
    return out;
}

}  // namespace vdbsplat
