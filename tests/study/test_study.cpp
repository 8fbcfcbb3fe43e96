// tests/study/test_study.cpp — the study's library parts: views and the zoom ladder, list
// parsing and ids, the heat map's scale and ramp, the crop window, metrics.csv/json, the SVG
// plots and the report's HTML (escaping, one <img> per picture, the self-check element).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "study/error_map.h"
#include "study/report.h"
#include "study/spec.h"
#include "study/views.h"
#include "util/parse.h"
#include "support/error_of.h"
#include "util/error.h"

namespace vdbsplat::study {
namespace {

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

TEST(StudyViews, StandardAndLadder) {
    const auto s = standardViews();
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s[0].distance, 8.0);
    EXPECT_EQ(s[1].distance, 1.0);
    EXPECT_EQ(s[2].distance, 0.35);
    EXPECT_EQ(s[2].id, "d0_35");
    const auto l = zoomLadder(2.0);
    ASSERT_EQ(l.size(), 7u);
    const double zooms[] = {0.125, 0.25, 0.5, 1, 2, 4, 8};
    for (size_t i = 0; i < 7; ++i) {
        EXPECT_DOUBLE_EQ(l[i].distance, 2.0 / zooms[i]);
        EXPECT_DOUBLE_EQ(l[i].zoom(), zooms[i] / 2.0);  // zoom against the framed view
    }
    EXPECT_EQ(l[0].label, "zoom 1/8x (distance 16)");
    EXPECT_THROW(zoomLadder(0.0), Error);
    EXPECT_THROW(zoomLadder(std::nan("")), Error);
    EXPECT_THROW(zoomLadder(-1.0), Error);
    // The ladder at base 1 shares distances 8 and 1 with the standard views: kept once, first label.
    std::vector<View> both = zoomLadder(1.0);
    for (const View& v : standardViews()) both.push_back(v);
    const auto merged = withoutRepeats(both);
    EXPECT_EQ(merged.size(), 8u);
    EXPECT_EQ(merged[0].label, "zoom 1/8x (distance 8)");
    EXPECT_EQ(merged.back().id, "d0_35");
}

TEST(StudyViews, IdsAndLists) {
    EXPECT_EQ(viewId(0.125), "d0_125");
    EXPECT_EQ(viewId(1e7), "d1ep07");
    EXPECT_EQ(safeId("engine_256x256x128"), "engine_256x256x128");
    EXPECT_EQ(safeId("a b/c"), "a_b_c");
    EXPECT_EQ(safeId(""), "volume");
    EXPECT_EQ(safeId(".."), "volume");
    EXPECT_EQ(safeId(std::string(100, 'x')).size(), 48u);
    EXPECT_EQ(splitList(" a, b ,c", "--x"), (std::vector<std::string>{"a", "b", "c"}));
    EXPECT_NE(test::errorOf([] { splitList("", "--modes"); }).find("--modes: empty item"), std::string::npos);
    EXPECT_THROW(splitList("a,", "--x"), Error);
    EXPECT_THROW(splitList("a,,b", "--x"), Error);
    EXPECT_EQ(fnv1a(""), "cbf29ce484222325");  // the FNV-1a 64 offset basis
    EXPECT_NE(fnv1a("a"), fnv1a("b"));
}

TEST(StudyHeat, ScaleAndRamp) {
    EXPECT_EQ(heatPosition(0.0), 0.0);
    EXPECT_EQ(heatPosition(kHeatLow), 0.0);
    EXPECT_EQ(heatPosition(kHeatHigh), 1.0);
    EXPECT_EQ(heatPosition(5.0), 1.0);
    EXPECT_EQ(heatPosition(std::nan("")), 1.0);
    EXPECT_NEAR(heatPosition(std::sqrt(kHeatLow * kHeatHigh)), 0.5, 1e-12);  // logarithmic
    double last = -1;
    for (double e = 1e-4; e < 1; e *= 1.3) {
        EXPECT_GE(heatPosition(e), last);
        last = heatPosition(e);
    }
    EXPECT_EQ(heatHex(0.0), "#440154");  // viridis' ends
    EXPECT_EQ(heatHex(1.0), "#fde725");
    // Brighter with more error (luma rises along the ramp).
    auto luma = [](double t) { const auto c = heatColour(t); return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
    for (int k = 1; k <= 16; ++k) EXPECT_GT(luma(k / 16.0), luma((k - 1) / 16.0));
}

TEST(StudyHeat, ErrorsCropAndWorstWindow) {
    Image ref(64, 48), im(64, 48);
    for (auto& p : im.pixels) p = glm::vec4(0.0f);
    // An error blob around (50, 10).
    for (int y = 4; y < 16; ++y)
        for (int x = 44; x < 56; ++x) im.at(x, y) = glm::vec4(1.0f);
    const auto e = pixelErrors(im, ref);
    EXPECT_EQ(e[0], 0.0);
    EXPECT_NEAR(e[size_t(10) * 64 + 50], 1.0, 1e-12);
    EXPECT_EQ(cropSide(64, 48), 12);
    EXPECT_EQ(cropSide(20, 20), 8);
    EXPECT_EQ(cropSide(6, 100), 6);
    const CropWindow w = worstWindow({e}, 64, 48);
    EXPECT_EQ(w.size, 12);
    EXPECT_TRUE(w.x <= 50 && 50 < w.x + w.size && w.y <= 10 && 10 < w.y + w.size) << w.x << "," << w.y;
    const CropWindow none = worstWindow({std::vector<double>(64 * 48, 0.0)}, 64, 48);
    EXPECT_EQ(none.x, (64 - 12) / 2);
    const Image c = crop(im, w);
    EXPECT_EQ(c.width, 12);
    EXPECT_EQ(c.at(0, 0), im.at(w.x, w.y));
    EXPECT_THROW(crop(im, {60, 0, 12}), Error);
    EXPECT_THROW(pixelErrors(Image(2, 2), ref), Error);
    const Image h = heatMap(e, 64, 48);
    EXPECT_EQ(h.at(0, 0).w, 1.0f);
}

StudyResult sampleStudy() {
    StudyResult s;
    s.command = "vdbsplat study a<b>.vdb -o out";
    s.width = s.height = 32;
    s.spp = 4;
    s.tf = "grey";
    s.modes = {"hybrid", "point"};
    s.kernels = {"gaussian"};
    VolumeResult vol{"sphere", "a<b>.vdb", "density", 100, "grey", {}};
    KernelResult k{"gaussian", {}};
    for (const View& v : standardViews()) {
        ViewResult vr;
        vr.view = v;
        vr.referenceSeconds = 1.5;
        vr.referenceImage = "images/" + v.id + "/reference.png";
        vr.referenceCrop = "images/" + v.id + "/reference-crop.png";
        for (const auto& m : s.modes) {
            ModeResult r;
            r.mode = m;
            r.metrics.psnr = m == "hybrid" ? std::numeric_limits<double>::infinity() : 30.0 + v.distance;
            r.metrics.ssim = 0.9;
            r.seconds = 0.01 * v.distance;
            r.points = 3, r.splats = 1;
            r.image = "images/" + v.id + "/" + m + ".png";
            r.errorImage = "images/" + v.id + "/" + m + "-error.png";
            r.cropImage = "images/" + v.id + "/" + m + "-crop.png";
            vr.modes.push_back(r);
        }
        k.views.push_back(vr);
    }
    vol.kernels.push_back(k);
    s.volumes.push_back(vol);
    return s;
}

TEST(StudyReport, CsvAndJson) {
    const StudyResult s = sampleStudy();
    const std::string csv = metricsCsv(s);
    EXPECT_EQ(count(csv, "\n"), 1u + 3 * 2);
    EXPECT_EQ(csv.substr(0, csv.find('\n')), csvHeader());
    EXPECT_NE(csv.find(",hybrid,inf,"), std::string::npos);
    EXPECT_NE(csv.find(",point,38.00,"), std::string::npos);
    StudyResult odd = s;
    odd.volumes[0].grid = "a,\"b\"";
    EXPECT_NE(metricsCsv(odd).find("\nsphere,\"a,\"\"b\"\"\",grey,gaussian,"), std::string::npos) << metricsCsv(odd);
    const auto j = metricsJson(s);
    ASSERT_EQ(j["rows"].size(), 6u);
    EXPECT_TRUE(j["rows"][0]["psnr_db"].is_null());
    EXPECT_EQ(j["rows"][1]["psnr_db"], 38.0);
    EXPECT_DOUBLE_EQ(j["rows"][1]["zoom"].get<double>(), 0.125);
    EXPECT_DOUBLE_EQ(j["rows"][1]["splat_fraction"].get<double>(), 0.25);
}

TEST(StudyReport, PlotsDrawEverySeries) {
    Plot p{"t<1>", "zoom", "PSNR", false, {}};
    p.series.push_back({"a", "#000", false, {0.125, 1, 8}, {20, 30, 40}});
    p.series.push_back({"b", "#111", true, {0.125, 1, 8}, {25, std::nan(""), std::numeric_limits<double>::infinity()}});
    const std::string svg = plotSvg(p);
    EXPECT_EQ(svg.rfind("<svg class=\"plot\"", 0), 0u);
    EXPECT_EQ(count(svg, "<polyline"), 2u);
    EXPECT_EQ(count(svg, "<circle"), 4u);  // NaN and inf left out
    EXPECT_NE(svg.find("t&lt;1&gt;"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_NE(svg.find(">1/8×<"), std::string::npos);
    // A log axis with one point and an empty series still makes a valid picture.
    Plot q{"t", "zoom", "s", true, {{"only", "#000", false, {2}, {0.5}}, {"none", "#111", false, {}, {}}}};
    const std::string one = plotSvg(q);
    EXPECT_EQ(count(one, "<circle"), 1u);
    EXPECT_EQ(one.find("nan"), std::string::npos);
    EXPECT_EQ(one.find("inf"), std::string::npos);
}

TEST(StudyReport, HtmlNamesEveryPictureAndEscapes) {
    const StudyResult s = sampleStudy();
    const std::string html = reportHtml(s);
    EXPECT_EQ(count(html, "<img "), 3u * (2 + 3 * 2));
    EXPECT_EQ(count(html, "<svg class=\"plot\""), 3u);
    EXPECT_EQ(count(html, "<svg class=\"colourbar\""), 3u);
    EXPECT_EQ(count(html, "<tr class=\"first\">"), 3u);
    EXPECT_NE(html.find("id=\"selfcheck\""), std::string::npos);
    EXPECT_NE(html.find("a&lt;b&gt;.vdb"), std::string::npos);
    EXPECT_EQ(html.find("a<b>"), std::string::npos);
    EXPECT_EQ(html.find("https://"), std::string::npos);
    EXPECT_EQ(htmlEscape("\"'&"), "&quot;&#39;&amp;");
}

TEST(StudySpec, FileToArguments) {
    const auto a = parseSpec(R"({"volumes": ["a.vdb", "b c.vdb"], "modes": ["hybrid", "splat"], "distances": [2, 0.5],
                                 "size": [160, 120], "spp": 16, "tf": "ct-bone", "threshold": 1.5})",
                             "s.json");
    ASSERT_EQ(a.size(), 7u);
    std::vector<std::string> flat;
    for (const auto& x : a) flat.insert(flat.end(), x.args.begin(), x.args.end());
    const std::vector<std::string> expected{"--distances", "2,0.5", "--modes", "hybrid,splat", "--size", "160x120",
                                            "--spp", "16", "--tf", "ct-bone", "--threshold", "1.5", "a.vdb", "b c.vdb"};
    std::vector<std::string> sortedFlat = flat, sortedExpected = expected;
    std::sort(sortedFlat.begin(), sortedFlat.end());
    std::sort(sortedExpected.begin(), sortedExpected.end());
    EXPECT_EQ(sortedFlat, sortedExpected);
    auto err = [](const std::string& text) { return test::errorOf([&] { parseSpec(text, "s.json"); }); };
    EXPECT_EQ(err("{}").rfind("s.json: volumes: missing", 0), 0u);
    EXPECT_NE(err(R"({"volumes": ["a"], "size": [1.5, 2]})").find("size[0]: expected an integer"), std::string::npos);
    EXPECT_NE(err(R"({"volumes": ["a"], "lod": null})").find("lod: expected a number, got null"), std::string::npos);
    EXPECT_NE(err(R"({"volumes": [""]})").find("volumes[0]: empty string"), std::string::npos);
    EXPECT_NE(err(std::string(kMaxSpecBytes + 1, ' ')).find("larger than 1 MB"), std::string::npos);
    EXPECT_NE(err(std::string(100000, '[')).find("nested deeper"), std::string::npos);
    EXPECT_NE(err("{\"volumes\": [\"a\"], \"tf\": \"x\\u0000y\"}").find("NUL"), std::string::npos);
}

}  // namespace
}  // namespace vdbsplat::study
