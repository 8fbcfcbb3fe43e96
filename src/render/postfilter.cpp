// render/postfilter.cpp — sub-pixel grid and the image-space prefilter (see postfilter.h).
#include "render/postfilter.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "footprint/prefilter.h"
#include "util/error.h"

namespace vdbsplat {

SubpixelGrid makeSubpixelGrid(int k, double prefilterVariance) {
    if (k < 1) throw Error("--subpixels: must be at least 1");
    SubpixelGrid g;
    g.k = k;
    // V_s/k² may not exceed V_h: keep at least a quarter of the low-pass for the image.
    g.fineVariance = std::min(kSubpixelPrefilterVariance, 0.75 * prefilterVariance * k * k);
    g.magnifiedVariance = std::min(kSubpixelMagnifiedVariance, g.fineVariance);
    g.postVariance = prefilterVariance - g.magnifiedVariance / (double(k) * k);
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

namespace {
/// The separable filter a band of output rows at a time (postfilterInto): the band's sub-pixel rows
/// filtered horizontally into its thread's buffer, then vertically into @p out.
template <class Frame>
void filterBands(const Frame& fine, const SubpixelGrid& grid, int width, int height, Image& out, int x0, int y0) {
    const PostfilterTaps taps = postfilterTaps(grid);
    const int k = grid.k, n = int(taps.weights.size());
    if (fine.width != k * (width + 2 * grid.border) || fine.height != k * (height + 2 * grid.border))
        throw Error("postfilter: the sub-pixel image does not match the grid");
    if (width < 0 || height < 0 || x0 < 0 || y0 < 0 || x0 + width > out.width || y0 + height > out.height)
        throw Error("postfilter: the output rectangle lies outside the image");
    adviseRowsWritten(out, y0, height, width);
    constexpr int kBand = 16;  // output rows a band (a simple partition: exactly this many, the last fewer)
    tbb::enumerable_thread_specific<std::vector<glm::vec4>> buffers;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, height, kBand),
        [&](const tbb::blocked_range<int>& r) {
            // Output row y reads sub-pixel rows k·(y + border) + first + j, j < n: the band's are
            // `count` rows from s0, and row y's first is k·(y − r.begin()) of them.
            const int s0 = k * (r.begin() + grid.border) + taps.first;
            const int count = k * (r.end() - 1 - r.begin()) + n;
            std::vector<glm::vec4>& rows = buffers.local();
            if (rows.size() < size_t(count) * size_t(width)) rows.resize(size_t(count) * size_t(width));
            for (int j = 0; j < count; ++j)
                for (int x = 0; x < width; ++x) {
                    const int first = k * (x + grid.border) + taps.first;
                    glm::vec4 sum(0.f);
                    for (int t = 0; t < n; ++t) sum += taps.weights[size_t(t)] * fine.at(first + t, s0 + j);
                    rows[size_t(j) * size_t(width) + size_t(x)] = sum;
                }
            for (int y = r.begin(); y < r.end(); ++y) {
                const size_t base = size_t(k) * size_t(y - r.begin());
                for (int x = 0; x < width; ++x) {
                    glm::vec4 sum(0.f);
                    for (int t = 0; t < n; ++t) sum += taps.weights[size_t(t)] * rows[(base + size_t(t)) * size_t(width) + size_t(x)];
                    out.at(x0 + x, y0 + y) = sum;
                }
            }
        },
        tbb::simple_partitioner());
}
}  // namespace

void postfilterInto(const FrameView& fine, const SubpixelGrid& grid, int width, int height, Image& out, int x0, int y0) {
    filterBands(fine, grid, width, height, out, x0, y0);
}

void postfilterInto(const Image& fine, const SubpixelGrid& grid, int width, int height, Image& out, int x0, int y0) {
    filterBands(fine, grid, width, height, out, x0, y0);
}

Image postfilterImage(const Image& fine, const SubpixelGrid& grid, int width, int height) {
    Image out(width, height);
    postfilterInto(fine, grid, width, height, out, 0, 0);
    return out;
}

}  // namespace vdbsplat
