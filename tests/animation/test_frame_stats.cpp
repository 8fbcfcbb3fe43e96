// tests/animation/test_frame_stats.cpp — flicker F_t, frames.csv rows, switch markers, plot.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "animation/frame_stats.h"
#include "metrics/metrics.h"
#include "util/error.h"

namespace vdbsplat::animation {
namespace {

Image noise(int w, int h, unsigned seed) {
    Image im(w, h);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.05f, 0.6f);
    for (auto& p : im.pixels) p = glm::vec4(u(rng), u(rng), u(rng), 1.0f);
    return im;
}

/// Adds @p offset to every channel's display value (as metrics see it).
Image shiftedDisplay(const Image& in, double offset) {
    Image out = in;
    for (auto& p : out.pixels)
        for (int c = 0; c < 3; ++c) {
            const double d = displayValue(p[c]) + offset;
            p[c] = float(d <= 0.04045 ? d / 12.92 : std::pow((d + 0.055) / 1.055, 2.4));
        }
    return out;
}

TEST(Flicker, ZeroWhenForwardDiffersFromReferenceByAConstant) {
    const Image r0 = noise(24, 16, 1), r1 = noise(24, 16, 2);
    const Image i0 = shiftedDisplay(r0, 0.1), i1 = shiftedDisplay(r1, 0.1);
    EXPECT_NEAR(flicker(i1, i0, r1, r0), 0.0, 1e-6);
    EXPECT_EQ(flicker(r1, r0, r1, r0), 0.0);  // identical sequences
}

TEST(Flicker, MeasuresChangesTheReferenceDoesNotHave) {
    const Image r = noise(20, 20, 3);
    const Image i0 = r, i1 = shiftedDisplay(r, 0.05);  // static reference, forward brightens
    EXPECT_NEAR(flicker(i1, i0, r, r), 0.05, 1e-5);
    // Symmetric in the sign of the change.
    EXPECT_NEAR(flicker(i0, i1, r, r), 0.05, 1e-5);
    // One pixel popping by 1 in one channel: 1 / (3·N).
    Image base = r;
    base.at(3, 4).x = 0.0f;
    Image pop = base;
    pop.at(3, 4).x = 1.0f;
    EXPECT_NEAR(flicker(pop, base, r, r), 1.0 / (3.0 * 400.0), 1e-9);
}

TEST(Flicker, SizesMustMatch) {
    EXPECT_THROW(flicker(noise(4, 4, 1), noise(4, 5, 1), noise(4, 4, 1), noise(4, 4, 1)), Error);
    EXPECT_THROW(flicker(Image(), Image(), Image(), Image()), Error);
}

TEST(FramesCsv, RoundTrip) {
    FrameRecord r;
    r.frame = 7;
    r.time = 7;
    r.distance = 0.5;
    r.eye[0] = 1.5, r.eye[1] = -2, r.eye[2] = 3.25;
    r.fov = 30;
    r.seconds = 0.0123;
    r.points = 100, r.splats = 300, r.splatFraction = 0.75;
    r.marker = "cross";
    r.psnr = 41.25;
    r.flicker = 0.00125;
    r.referenceSeconds = 1.5;
    for (const bool ref : {false, true}) {
        const std::string row = csvRow(r, ref);
        const auto back = parseCsvRow(row, ref);
        ASSERT_TRUE(back) << row;
        EXPECT_EQ(csvRow(*back, ref), row);
        const std::string header = csvHeader(ref);
        EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
    }
    r.flicker.reset();  // first frame
    r.distance = NAN;   // keyframes
    const auto back = parseCsvRow(csvRow(r, true), true);
    ASSERT_TRUE(back);
    EXPECT_FALSE(back->flicker);
    EXPECT_TRUE(std::isnan(back->distance));
    EXPECT_FALSE(parseCsvRow("1,2,3", false));
    EXPECT_FALSE(parseCsvRow(csvRow(r, false), true));
}

TEST(Switches, CrossingAndSteps) {
    std::vector<FrameRecord> v(6);
    const double s[] = {0.0, 0.05, 0.3, 0.55, 0.6, 0.2};
    for (size_t i = 0; i < 6; ++i) v[i].splatFraction = s[i];
    markSwitches(v);
    EXPECT_EQ(v[0].marker, "");
    EXPECT_EQ(v[1].marker, "");       // +5 points
    EXPECT_EQ(v[2].marker, "step");   // +25 points, below half
    EXPECT_EQ(v[3].marker, "cross");  // 0.3 -> 0.55
    EXPECT_EQ(v[4].marker, "");
    EXPECT_EQ(v[5].marker, "cross");  // back below half
}

TEST(Plot, SelfContainedSvg) {
    std::vector<FrameRecord> v(5);
    for (size_t i = 0; i < 5; ++i) {
        v[i].frame = (long long)i;
        v[i].splatFraction = 0.2 * double(i);
        v[i].psnr = 40.0 + double(i);
        if (i) v[i].flicker = 0.001 * double(i);
    }
    v[4].psnr = INFINITY;
    markSwitches(v);
    const std::string svg = plotSvg(v, "title <&>");
    EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(std::count(svg.begin(), svg.end(), '<') - std::count(svg.begin(), svg.end(), '>'), 0);
    EXPECT_NE(svg.find("title &lt;&amp;&gt;"), std::string::npos);
    EXPECT_EQ(svg.find("href"), std::string::npos);  // nothing external
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_EQ(svg.find("inf"), std::string::npos);
    EXPECT_NE(svg.find("frame 3: cross"), std::string::npos);
}

}  // namespace
}  // namespace vdbsplat::animation
