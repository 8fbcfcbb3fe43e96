// tests/cli/test_cli_compare.cpp — `vdbsplat compare` end to end: the printed line,
// the JSON report, --help, and one-line errors with a non-zero exit for bad input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "image/image.h"
#include "metrics/metrics.h"
#include "support/cli.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::slurp;

/// A scratch folder for one test, removed afterwards.
class CompareCli : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }

    /// Runs `vdbsplat compare <args>` and captures its exit code, stdout and stderr.
    CliResult compare(const std::string& args) const { return test::runVdbsplat("compare " + args, scratch_.dir()); }

    /// Expects a failure with exactly one line "vdbsplat: error: …" containing @p what.
    void expectError(const CliResult& r, const std::string& what) const { test::expectOneLineError(r, what); }

    test::ScratchDir scratch_{"compare"};
};

Image gradient(int w, int h, float offset) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float v = std::min(1.f, float(x) / float(w) + offset);
            img.at(x, y) = glm::vec4(v, 0.5f * v, float(y) / float(h), 1.f);
        }
    return img;
}

/// The number after "key=" in the printed line.
std::string field(const std::string& line, const std::string& key) {
    const size_t at = line.find(key + "=");
    if (at == std::string::npos) return "";
    const size_t start = at + key.size() + 1;
    return line.substr(start, line.find(' ', start) - start);
}

TEST_F(CompareCli, IdenticalImagesPrintInfinitePsnr) {
    writeImage(path("a.exr"), gradient(32, 16, 0.f));
    const CliResult r = compare("'" + path("a.exr") + "' '" + path("a.exr") + "'");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    EXPECT_EQ(field(r.out, "psnr"), "inf");
    EXPECT_EQ(field(r.out, "ssim"), "1");
    EXPECT_EQ(field(r.out, "size"), "32x16\n");
}

TEST_F(CompareCli, PrintsAndWritesTheLibraryMetrics) {
    const Image a = gradient(40, 30, 0.05f), b = gradient(40, 30, 0.f);
    writeImage(path("a.exr"), a);
    writeImage(path("b.exr"), b);
    const ImageMetrics expected = compareImages(readImage(path("a.exr")), readImage(path("b.exr")));
    const CliResult r = compare("'" + path("a.exr") + "' '" + path("b.exr") + "' --json '" + path("m.json") + "'");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NEAR(std::stod(field(r.out, "psnr")), expected.psnr, 1e-3);
    const auto j = nlohmann::json::parse(slurp(path("m.json")));
    EXPECT_DOUBLE_EQ(j.at("psnr_db").get<double>(), expected.psnr);
    EXPECT_DOUBLE_EQ(j.at("mse").get<double>(), expected.mse);
    EXPECT_DOUBLE_EQ(j.at("ssim").get<double>(), expected.ssim);
    EXPECT_DOUBLE_EQ(j.at("max_abs_error").get<double>(), expected.maxAbsError);
    EXPECT_EQ(j.at("width"), 40);
    EXPECT_EQ(j.at("height"), 30);
    EXPECT_EQ(j.at("identical"), false);
    EXPECT_GT(expected.psnr, 10.0);
    EXPECT_LT(expected.psnr, 60.0);
}

TEST_F(CompareCli, PngAgainstItsEightBitSelfAndIdenticalJson) {
    writeImage(path("a.png"), gradient(20, 20, 0.1f));
    const CliResult r = compare("'" + path("a.png") + "' '" + path("a.png") + "' --json=" + path("m.json"));
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(path("m.json")));
    EXPECT_TRUE(j.at("psnr_db").is_null());
    EXPECT_EQ(j.at("identical"), true);
    EXPECT_EQ(j.at("mse"), 0.0);
}

TEST_F(CompareCli, HelpExitsZero) {
    const CliResult r = compare("--help");
    EXPECT_EQ(r.rc, 0);
    EXPECT_NE(r.out.find("usage: vdbsplat compare IMAGE REFERENCE [--json FILE]"), std::string::npos);
}

TEST_F(CompareCli, MissingImage) {
    writeImage(path("a.exr"), gradient(8, 8, 0.f));
    expectError(compare("'" + path("a.exr") + "' '" + path("nope.exr") + "'"), path("nope.exr") + ": no such file");
}

TEST_F(CompareCli, UnreadableImage) {
    writeImage(path("a.png"), gradient(8, 8, 0.f));
    std::ofstream(path("text.png")) << "not an image\nat all\n";
    expectError(compare("'" + path("text.png") + "' '" + path("a.png") + "'"), path("text.png") + ":");
}

TEST_F(CompareCli, SizeMismatch) {
    writeImage(path("a.exr"), gradient(8, 8, 0.f));
    writeImage(path("b.exr"), gradient(9, 8, 0.f));
    const CliResult r = compare("'" + path("a.exr") + "' '" + path("b.exr") + "' --json '" + path("m.json") + "'");
    expectError(r, "(8x8) and " + path("b.exr") + " (9x8) differ in size");
    EXPECT_FALSE(fs::exists(path("m.json")));
}

TEST_F(CompareCli, WrongArguments) {
    writeImage(path("a.exr"), gradient(8, 8, 0.f));
    expectError(compare("'" + path("a.exr") + "'"), "compare needs IMAGE and REFERENCE, got 1");
    expectError(compare(""), "compare needs IMAGE and REFERENCE, got 0");
    expectError(compare("'" + path("a.exr") + "' '" + path("a.exr") + "' --psnr"), "unknown option '--psnr'");
    expectError(compare("'" + path("a.exr") + "' '" + path("a.exr") + "' --json"), "--json: missing value");
}

TEST_F(CompareCli, JsonIntoMissingFolder) {
    writeImage(path("a.exr"), gradient(8, 8, 0.f));
    const std::string json = path("no/such/dir/m.json");
    expectError(compare("'" + path("a.exr") + "' '" + path("a.exr") + "' --json '" + json + "'"), json);
    EXPECT_FALSE(fs::exists(json));
}

}  // namespace
}  // namespace vdbsplat
