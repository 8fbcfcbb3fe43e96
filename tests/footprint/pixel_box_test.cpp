// tests/footprint/pixel_box_test.cpp — pixelRange against brute force: the pixels of an image
// whose centres (i + 0.5, j + 0.5) lie in the box, for boxes on pixel centres, between them,
// off the image, infinite and NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "footprint/pixel_box.h"

namespace vdbsplat {
namespace {

PixelRange bruteForce(const PixelBox& box, int width, int height) {
    PixelRange r{width, height, -1, -1};
    bool any = false;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double cx = x + 0.5, cy = y + 0.5;
            if (cx >= box.lo.x && cx <= box.hi.x && cy >= box.lo.y && cy <= box.hi.y) {
                r.x0 = std::min(r.x0, x), r.x1 = std::max(r.x1, x);
                r.y0 = std::min(r.y0, y), r.y1 = std::max(r.y1, y);
                any = true;
            }
        }
    return any ? r : PixelRange{};
}

TEST(PixelBox, RangeMatchesBruteForce) {
    constexpr int kW = 13, kH = 9;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-6.0, 20.0);
    std::uniform_int_distribution<int> k(-6, 20);
    const double inf = std::numeric_limits<double>::infinity();
    for (int trial = 0; trial < 20000; ++trial) {
        PixelBox b;
        // Half the corners exactly on pixel centres or edges (the rounding cases), the rest anywhere.
        const auto coord = [&] { return trial % 2 ? u(rng) : 0.5 * k(rng); };
        b.lo = {coord(), coord()}, b.hi = {coord(), coord()};
        if (trial % 97 == 0) b.lo.x = -inf;
        if (trial % 89 == 0) b.hi.y = inf;
        const PixelRange got = pixelRange(b, kW, kH), want = bruteForce(b, kW, kH);
        ASSERT_EQ(got.empty(), want.empty()) << b.lo.x << "," << b.lo.y << " " << b.hi.x << "," << b.hi.y;
        if (want.empty()) continue;
        ASSERT_EQ(got.x0, want.x0) << b.lo.x;
        ASSERT_EQ(got.x1, want.x1) << b.hi.x;
        ASSERT_EQ(got.y0, want.y0) << b.lo.y;
        ASSERT_EQ(got.y1, want.y1) << b.hi.y;
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(pixelRange(PixelBox{{nan, 0.0}, {5.0, 5.0}}, kW, kH).empty());
    EXPECT_TRUE(pixelRange(PixelBox{{0.0, 0.0}, {5.0, nan}}, kW, kH).empty());
    const PixelRange whole = pixelRange(PixelBox{{-inf, -inf}, {inf, inf}}, kW, kH);
    EXPECT_EQ(whole.x0, 0);
    EXPECT_EQ(whole.y0, 0);
    EXPECT_EQ(whole.x1, kW - 1);
    EXPECT_EQ(whole.y1, kH - 1);
}

}  // namespace
}  // namespace vdbsplat
