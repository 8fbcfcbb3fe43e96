// tests/render/test_postfilter.cpp — the image-space prefilter of render/postfilter.h against
// brute force: the sub-pixel camera's pixel map, the separable Gaussian against a direct 2D
// sum over sub-pixel centres, unit weight sums, and thread-count invariance.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "camera/camera.h"
#include "footprint/prefilter.h"
#include "render/postfilter.h"
#include "render/settings.h"

namespace vdbsplat {
namespace {

Image randomImage(int w, int h, uint32_t seed) {
    Image image(w, h);
    uint32_t s = seed;
    const auto next = [&] { return float((s = s * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    for (auto& p : image.pixels) p = glm::vec4(next(), next(), next(), next());
    return image;
}

/// The oracle: each output pixel is the normalised sum over every sub-pixel centre within
/// the cutoff (per axis) of exp(−(dx² + dy²)/2V), evaluated in double.
Image bruteForce(const Image& fine, const SubpixelGrid& g, int width, int height) {
    Image out(width, height);
    const double reach = kPrefilterCutoffSigmas * std::sqrt(g.postVariance);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            glm::dvec4 sum(0.0);
            double weights = 0.0;
            for (int j = 0; j < fine.height; ++j)
                for (int i = 0; i < fine.width; ++i) {
                    const double dx = (i + 0.5) / g.k - g.border - (x + 0.5);
                    const double dy = (j + 0.5) / g.k - g.border - (y + 0.5);
                    if (std::abs(dx) > reach + 1e-9 || std::abs(dy) > reach + 1e-9) continue;
                    const double w = std::exp(-0.5 * (dx * dx + dy * dy) / g.postVariance);
                    sum += w * glm::dvec4(fine.at(i, j));
                    weights += w;
                }
            out.at(x, y) = glm::vec4(sum / weights);
        }
    return out;
}

TEST(Postfilter, VariancesAddUpToThePrefilter) {
    for (int k = 1; k <= kMaxSubpixels; ++k) {
        const SubpixelGrid g = makeSubpixelGrid(k, kPrefilterVariance);
        // A magnified primitive's total low-pass is V_h; a minified one's V_h + (V_s − V_m)/k².
        EXPECT_NEAR(g.magnifiedVariance / (k * k) + g.postVariance, kPrefilterVariance, 1e-12) << k;
        EXPECT_GT(g.magnifiedVariance, 0.0) << k;
        EXPECT_LE(g.magnifiedVariance, g.fineVariance) << k;
        EXPECT_GT(g.postVariance, 0.0) << k;
        EXPECT_GE(g.border, kPrefilterCutoffSigmas * std::sqrt(g.postVariance)) << k;
    }
    EXPECT_THROW(makeSubpixelGrid(0, 1.0), std::exception);
}

TEST(Postfilter, TapsSumToOneAndAreSymmetric) {
    for (int k = 1; k <= 4; ++k) {
        const PostfilterTaps taps = postfilterTaps(makeSubpixelGrid(k, kPrefilterVariance));
        double sum = 0.0;
        for (float w : taps.weights) sum += w;
        EXPECT_NEAR(sum, 1.0, 1e-6) << k;
        const size_t n = taps.weights.size();
        for (size_t j = 0; j < n; ++j) EXPECT_NEAR(taps.weights[j], taps.weights[n - 1 - j], 1e-7) << k;
    }
}

TEST(Postfilter, SubpixelCameraMapsPixelsToSubpixels) {
    const Camera camera(glm::dvec3(3, -40, 12), glm::dvec3(0.5, 1, -2), glm::dvec3(0, 0, 1), 30.0, 64, 48);
    for (int k : {1, 2, 3}) {
        const SubpixelGrid g = makeSubpixelGrid(k, kPrefilterVariance);
        const Camera fine = subpixelCamera(camera, g);
        EXPECT_EQ(fine.width(), k * (64 + 2 * g.border));
        EXPECT_EQ(fine.height(), k * (48 + 2 * g.border));
        EXPECT_NEAR(fine.focal(), k * camera.focal(), 1e-9 * camera.focal());
        for (const glm::dvec3 w : {glm::dvec3(1, 2, 3), glm::dvec3(-4, 0.5, 1), glm::dvec3(6, -3, -5)}) {
            const PixelCoord p = camera.project(camera.toView(w)), q = fine.project(fine.toView(w));
            EXPECT_NEAR(q.x, k * (p.x + g.border), 1e-7) << k;
            EXPECT_NEAR(q.y, k * (p.y + g.border), 1e-7) << k;
        }
    }
}

TEST(Postfilter, SeparableFilterMatchesBruteForce) {
    for (int k : {1, 2, 3}) {
        const SubpixelGrid g = makeSubpixelGrid(k, kPrefilterVariance);
        const int w = 11, h = 7;
        const Image fine = randomImage(k * (w + 2 * g.border), k * (h + 2 * g.border), 17u + k);
        const Image fast = postfilterImage(fine, g, w, h), slow = bruteForce(fine, g, w, h);
        for (size_t i = 0; i < fast.pixels.size(); ++i)
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(fast.pixels[i][c], slow.pixels[i][c], 2e-6) << "k " << k << " pixel " << i;
    }
}

// Into a rectangle of a larger image, straight from a compositor's frame (radiance and T): the
// rectangle holds brute force's pixels over several bands of rows (the last one short), the same
// values as postfilterImage on the frame copied into an Image, and nothing else is written; a
// rectangle outside the image is refused.
TEST(Postfilter, IntoARectangleFromTheFrame) {
    for (int k : {1, 2, 3}) {
        const SubpixelGrid g = makeSubpixelGrid(k, kPrefilterVariance);
        const int w = 23, h = 37, fw = k * (w + 2 * g.border), fh = k * (h + 2 * g.border);
        const Image fine = randomImage(fw, fh, 31u + k);
        std::vector<glm::vec3> color(fine.pixels.size());
        std::vector<float> transmittance(fine.pixels.size());
        Image asFrame(fw, fh);
        for (size_t i = 0; i < fine.pixels.size(); ++i) {
            color[i] = glm::vec3(fine.pixels[i]), transmittance[i] = 1.f - fine.pixels[i].w;
            asFrame.pixels[i] = glm::vec4(color[i], 1.f - transmittance[i]);
        }
        const FrameView frame{color.data(), transmittance.data(), fw, fh};
        const glm::vec4 sentinel(-7.f);
        Image out(w + 9, h + 5);
        for (auto& p : out.pixels) p = sentinel;
        const int x0 = 6, y0 = 3;
        postfilterInto(frame, g, w, h, out, x0, y0);
        const Image whole = postfilterImage(asFrame, g, w, h), slow = bruteForce(asFrame, g, w, h);
        for (int y = 0; y < out.height; ++y)
            for (int x = 0; x < out.width; ++x) {
                const bool inside = x >= x0 && x < x0 + w && y >= y0 && y < y0 + h;
                if (!inside) {
                    ASSERT_EQ(out.at(x, y), sentinel) << "k " << k << " pixel " << x << "," << y;
                    continue;
                }
                ASSERT_EQ(out.at(x, y), whole.at(x - x0, y - y0)) << "k " << k << " pixel " << x << "," << y;
                for (int c = 0; c < 4; ++c) ASSERT_NEAR(out.at(x, y)[c], slow.at(x - x0, y - y0)[c], 2e-6);
            }
        EXPECT_THROW(postfilterInto(frame, g, w, h, out, 10, 0), Error);
        EXPECT_THROW(postfilterInto(frame, g, w + 1, h, out, 0, 0), Error);
    }
}

TEST(Postfilter, KeepsConstantsAndEnergy) {
    const SubpixelGrid g = makeSubpixelGrid(2, kPrefilterVariance);
    const int w = 20, h = 20;
    Image fine(2 * (w + 2 * g.border), 2 * (h + 2 * g.border));
    for (auto& p : fine.pixels) p = glm::vec4(0.25f, 0.5f, 0.75f, 1.f);
    for (const auto& p : postfilterImage(fine, g, w, h).pixels)
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(p[c], fine.pixels[0][c], 1e-6);
    // One bright sub-pixel well inside: the output sums to its value over k² (a sub-pixel's
    // area), up to the imbalance of the truncated taps between the k sub-pixel phases.
    for (auto& p : fine.pixels) p = glm::vec4(0.f);
    fine.at(2 * (10 + g.border) + 1, 2 * (9 + g.border)) = glm::vec4(4.f);
    double sum = 0.0;
    for (const auto& p : postfilterImage(fine, g, w, h).pixels) sum += p.x;
    EXPECT_NEAR(sum, 1.0, 1e-3);
}

TEST(Postfilter, DoesNotDependOnThreadCount) {
    const SubpixelGrid g = makeSubpixelGrid(2, kPrefilterVariance);
    const int w = 150, h = 90;
    const Image fine = randomImage(2 * (w + 2 * g.border), 2 * (h + 2 * g.border), 5u);
    Image one;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = postfilterImage(fine, g, w, h);
    }
    const Image many = postfilterImage(fine, g, w, h);
    for (size_t i = 0; i < one.pixels.size(); ++i) ASSERT_EQ(one.pixels[i], many.pixels[i]) << i;
}

}  // namespace
}  // namespace vdbsplat
