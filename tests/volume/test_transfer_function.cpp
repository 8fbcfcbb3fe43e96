// tests/volume/test_transfer_function.cpp — transfer functions: presets, interpolation,
// units, the baked table against evaluate(), JSON and ParaView files, and every kind of
// invalid file (rejected with one line naming the file and the reason).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "image/image.h"
#include "util/error.h"
#include "volume/transfer_function.h"
#include "support/error_of.h"

namespace vdbsplat {
namespace {

using test::errorOf;

namespace fs = std::filesystem;

/// A fresh folder under /tmp, removed at the end of the test.
class TempDir {
public:
    TempDir() {
        std::string pattern = "/tmp/vdbsplat-tf-XXXXXX";
        if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    /// Writes @p text to @p name inside the folder and returns its path.
    std::string write(const std::string& name, const std::string& text) const {
        const std::string p = path_ + "/" + name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

void expectSame(const Classified& a, const Classified& b, float tol) {
    EXPECT_NEAR(a.sigma, b.sigma, tol);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.color[c], b.color[c], tol) << "channel " << c;
}

// --- Presets ---------------------------------------------------------------------

TEST(TransferFunctionPresets, AllNamedPresetsExistAndAreValid) {
    ASSERT_EQ(TransferFunction::presetNames(), (std::vector<std::string>{"grey", "ct-bone", "fire"}));
    for (const auto& name : TransferFunction::presetNames()) {
        const TransferFunction tf = TransferFunction::preset(name);
        EXPECT_EQ(tf.name(), name);
        EXPECT_FALSE(tf.worldUnits()) << name;
        for (float x = 0.f; x <= 1.f; x += 1.f / 64) {
            const Classified c = tf.evaluate(x);
            EXPECT_GE(c.sigma, 0.f) << name << " x=" << x;
            EXPECT_LE(c.sigma, 0.5f) << name << " x=" << x;  // documented magnitudes: peak ≤ 0.5 per voxel
            for (int k = 0; k < 3; ++k) EXPECT_TRUE(c.color[k] >= 0.f && c.color[k] <= 1.f) << name;
        }
        EXPECT_FALSE(tf.bake(0.f, 1.f, 1.0).empty()) << name;
    }
}

TEST(TransferFunctionPresets, ControlPointsAndMidpointsInterpolate) {
    for (const auto& name : TransferFunction::presetNames()) {
        const TransferFunction tf = TransferFunction::preset(name);
        const auto& cs = tf.colors();
        for (size_t i = 0; i < cs.size(); ++i) {
            EXPECT_EQ(tf.evaluate(cs[i].x).color, cs[i].rgb) << name << " colour point " << i;
            if (i + 1 < cs.size()) {
                const glm::vec3 mid = tf.evaluate(0.5f * (cs[i].x + cs[i + 1].x)).color;
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(mid[k], 0.5f * (cs[i].rgb[k] + cs[i + 1].rgb[k]), 1e-6f);
            }
        }
        const auto& es = tf.extinction();
        for (size_t i = 0; i < es.size(); ++i) {
            EXPECT_FLOAT_EQ(tf.evaluate(es[i].x).sigma, es[i].sigma) << name << " extinction point " << i;
            if (i + 1 < es.size()) {
                EXPECT_NEAR(tf.evaluate(0.5f * (es[i].x + es[i + 1].x)).sigma, 0.5f * (es[i].sigma + es[i + 1].sigma),
                            1e-6f);
            }
        }
    }
}

TEST(TransferFunctionPresets, PinnedValues) {
    const TransferFunction grey = TransferFunction::preset("grey");
    EXPECT_FLOAT_EQ(grey.evaluate(0.5f).sigma, 0.25f);
    EXPECT_EQ(grey.evaluate(0.25f).color, glm::vec3(0.25f));
    EXPECT_EQ(grey.evaluate(-1.f).sigma, 0.f);  // clamped below
    EXPECT_EQ(grey.evaluate(2.f).sigma, 0.5f);  // clamped above

    const TransferFunction ct = TransferFunction::preset("ct-bone");
    EXPECT_EQ(ct.evaluate(0.05f).sigma, 0.f);                  // Engine air / noise is invisible
    EXPECT_EQ(ct.evaluate(0.12f).sigma, 0.f);
    EXPECT_NEAR(ct.evaluate(0.275f).sigma, 0.0055f, 1e-6f);     // soft tissue: faint
    EXPECT_NEAR(ct.evaluate(0.56f).sigma, 0.025f, 1e-6f);       // engine block: translucent
    EXPECT_NEAR(ct.evaluate(0.685f).sigma, 0.115f, 1e-6f);      // midpoint of 0.62–0.75
    EXPECT_FLOAT_EQ(ct.evaluate(1.f).sigma, 0.4f);              // dense metal / bone
    EXPECT_LT(ct.evaluate(0.3f).sigma * 10.f, ct.evaluate(0.9f).sigma);
    // A 100-voxel path through the Engine's main material (x ≈ 0.56) is translucent, not opaque.
    const float tau = 100.f * ct.evaluate(0.56f).sigma;
    EXPECT_GT(tau, 1.f);
    EXPECT_LT(tau, 5.f);

    const TransferFunction fire = TransferFunction::preset("fire");
    const glm::vec3 dark = fire.evaluate(0.25f).color, hot = fire.evaluate(1.f).color;
    EXPECT_GT(dark.x, 4.f * dark.y);                           // dark red
    EXPECT_TRUE(hot.x >= hot.y && hot.y >= hot.z && hot.z > 0.5f);  // yellow-white
    EXPECT_LT(fire.evaluate(0.1f).sigma, fire.evaluate(0.9f).sigma);
}

TEST(TransferFunctionPresets, UnknownPresetAndSpecAreRejected) {
    EXPECT_NE(errorOf([] { TransferFunction::preset("bone"); }).find("unknown transfer function preset 'bone'"),
              std::string::npos);
    const std::string msg = errorOf([] { TransferFunction::fromSpec("no-such-preset-or-file"); });
    EXPECT_EQ(msg, "unknown transfer function preset or file 'no-such-preset-or-file' (presets: grey, ct-bone, fire)");
    EXPECT_EQ(TransferFunction::fromSpec("fire").name(), "fire");
}

TEST(TransferFunctionPresets, NonFiniteValuesClassifyAsNothing) {
    const TransferFunction ct = TransferFunction::preset("ct-bone");
    EXPECT_EQ(ct.evaluate(NAN).sigma, 0.f);
    const ClassificationTable table = ct.bake(0.f, 1.f, 1.0);
    EXPECT_EQ(table(NAN).sigma, 0.f);
    EXPECT_EQ(table(INFINITY).sigma, 0.f);
    EXPECT_EQ(table(-INFINITY).color, glm::vec3(0.f));
}

// --- Baking ----------------------------------------------------------------------

TEST(TransferFunctionBake, WorldUnitsAreScaledByVoxelSize) {
    const auto world = TransferFunction::fromPoints("w", {{0.f, glm::vec3(1.f)}}, {{0.f, 0.f}, {1.f, 2.f}}, true);
    const auto voxel = TransferFunction::fromPoints("v", {{0.f, glm::vec3(1.f)}}, {{0.f, 0.f}, {1.f, 2.f}}, false);
    EXPECT_FLOAT_EQ(world.bake(0.f, 1.f, 0.25)(1.f).sigma, 0.5f);  // 2 per world unit × 0.25 world units per voxel
    EXPECT_FLOAT_EQ(world.bake(0.f, 1.f, 0.25)(0.5f).sigma, 0.25f);
    EXPECT_FLOAT_EQ(voxel.bake(0.f, 1.f, 0.25)(1.f).sigma, 2.f);   // already per voxel
    EXPECT_FLOAT_EQ(world.evaluate(1.f).sigma, 2.f);                // evaluate stays in the function's units
    EXPECT_NE(errorOf([&] { world.bake(0.f, 1.f, 0.0); }).find("positive voxel size"), std::string::npos);
    EXPECT_NE(errorOf([&] { voxel.bake(0.f, NAN, 1.0); }).find("not finite"), std::string::npos);
}

TEST(TransferFunctionBake, TableMatchesEvaluateOverTheRange) {
    const float lo = -3.f, hi = 7.f;  // a grid range that is not [0, 1]
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(lo, hi);
    for (const auto& name : TransferFunction::presetNames()) {
        const TransferFunction tf = TransferFunction::preset(name);
        const ClassificationTable table = tf.bake(lo, hi, 1.0);
        for (int n = 0; n < 20000; ++n) {
            const float v = u(rng);
            // Kinks fall between table entries: error ≤ slope change × one cell (1/4095).
            expectSame(table(v), tf.evaluate((v - lo) / (hi - lo)), 5e-4f);
        }
    }
}

// The presets (at most 16 linear pieces) classify through their pieces: the function itself to
// float rounding, kinks included, where the table's lerp rounds each kink over one entry. Steps
// (two points at one x, inside and at 1) take the later value at the step, as evaluate() does;
// world units scale σ; every x below transparentBelow() is σ = 0 exactly.
TEST(TransferFunctionBake, PiecesAreTheFunctionKinksAndStepsIncluded) {
    const float lo = -3.f, hi = 7.f;
    auto functions = std::vector<TransferFunction>{};
    for (const auto& name : TransferFunction::presetNames()) functions.push_back(TransferFunction::preset(name));
    functions.push_back(TransferFunction::fromPoints("steps", {{0.f, glm::vec3(0.f)}, {0.3f, glm::vec3(0.2f, 0.9f, 0.4f)},
                                                               {0.3f, glm::vec3(1.f)}, {1.f, glm::vec3(0.5f)}},
                                                     {{0.2f, 0.f}, {0.6f, 0.7f}, {0.6f, 0.1f}, {1.f, 0.3f}, {1.f, 2.f}}, true));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (const TransferFunction& tf : functions) {
        SCOPED_TRACE(tf.name());
        const double h = 0.5;
        const ClassificationTable table = tf.bake(lo, hi, h);
        const LinearPieces& pieces = table.pieces();
        ASSERT_GE(pieces.count, 1);
        const float perVoxel = tf.worldUnits() ? float(h) : 1.f;
        const auto expectFunction = [&](float x) {
            const float v = lo + x * (hi - lo);
            const float at = (table.indexOf(v)) / float(ClassificationTable::kSize - 1);  // x as the table sees it
            Classified want = tf.evaluate(std::clamp(at, 0.f, 1.f));
            want.sigma *= perVoxel;
            expectSame(table(v), want, 2e-6f);
            if (table.indexOf(v) < table.transparentBelow()) {
                EXPECT_EQ(table(v).sigma, 0.f) << x;
            }
        };
        for (int n = 0; n < 20000; ++n) expectFunction(u(rng));
        // Either side of every knot, within one table entry (where the table's lerp is off by
        // ~Δslope / 4095 / 4, beyond the tolerance for ct-bone's kinks).
        for (const float delta : {-3e-5f, 3e-5f}) {
            for (const auto& p : tf.colors()) expectFunction(std::clamp(p.x + delta, 0.f, 1.f));
            for (const auto& p : tf.extinction()) expectFunction(std::clamp(p.x + delta, 0.f, 1.f));
        }
    }
    const ClassificationTable steps = functions.back().bake(0.f, 1.f, 1.0);
    EXPECT_FLOAT_EQ(steps(0.3f).color.y, 1.f);
    EXPECT_NEAR(steps(0.2999f).color.y, 0.9f, 1e-3f);
    EXPECT_FLOAT_EQ(steps(1.f).sigma, 2.f);  // the step at 1: the last point
    EXPECT_NEAR(steps(0.9999f).sigma, 0.3f, 1e-3f);
    EXPECT_EQ(steps(0.2f).sigma, 0.f);
    EXPECT_EQ(steps.transparentBelow(), steps.pieces().knot[1]);  // σ rises from x = 0.2
}

// More than 16 pieces: no pieces, the table's lerp (its error bound); an all-zero σ is empty.
TEST(TransferFunctionBake, ManyPointsClassifyThroughTheTable) {
    std::vector<TransferFunction::ExtinctionPoint> sigma;
    for (int k = 0; k <= 20; ++k) sigma.push_back({float(k) / 20.f, float(k % 2)});
    const auto tf = TransferFunction::fromPoints("saw", {{0.f, glm::vec3(1.f)}}, sigma);
    const ClassificationTable table = tf.bake(0.f, 1.f, 1.0);
    EXPECT_EQ(table.pieces().count, 0);
    for (int n = 0; n <= 1000; ++n) {
        const float x = float(n) / 1000.f;
        expectSame(table(x), tf.evaluate(x), 20.f / 4095.f);  // slope 20: one entry's rounding of a kink
    }
    // A slope beyond float's range (σ near FLT_MAX across two knots a few ulps apart): the table.
    const auto cliff = TransferFunction::fromPoints("cliff", {{0.f, glm::vec3(1.f)}},
                                                    {{0.5f, 0.f}, {std::nextafter(0.5f, 1.f), 3e38f}});
    EXPECT_EQ(cliff.bake(0.f, 1.f, 1.0).pieces().count, 0);
    EXPECT_EQ(cliff.bake(0.f, 1.f, 1.0)(1.f).sigma, 3e38f);
    const auto zero = TransferFunction::fromPoints("z", {{0.f, glm::vec3(1.f)}, {0.5f, glm::vec3(0.f)}}, {{0.3f, 0.f}});
    EXPECT_GT(zero.bake(0.f, 1.f, 1.0).pieces().count, 0);
    EXPECT_TRUE(zero.bake(0.f, 1.f, 1.0).empty());
    // Pieces handed to a table are checked: knots out of order, or a slope that is not finite.
    LinearPieces bad;
    bad.count = 2, bad.knot[1] = 5000.f;
    EXPECT_NE(errorOf([&] { ClassificationTable(std::vector<Classified>(ClassificationTable::kSize), 0.f, 1.f, bad); })
                  .find("linear pieces"), std::string::npos);
    bad.knot[1] = 100.f, bad.slope[3][1] = INFINITY;
    EXPECT_NE(errorOf([&] { ClassificationTable(std::vector<Classified>(ClassificationTable::kSize), 0.f, 1.f, bad); })
                  .find("linear pieces"), std::string::npos);
}

// grey() (the compositor's one channel, composite/compositing.h): every value's colour grey, bit
// for bit, through the pieces and through the entries; one colour point off grey, anywhere, is not.
TEST(TransferFunctionBake, GreyTablesAreRecognised) {
    EXPECT_TRUE(TransferFunction::preset("grey").bake(0.f, 1.f, 1.0).grey());
    EXPECT_FALSE(TransferFunction::preset("ct-bone").bake(0.f, 1.f, 1.0).grey());
    EXPECT_FALSE(TransferFunction::preset("fire").bake(0.f, 1.f, 1.0).grey());
    std::vector<TransferFunction::ExtinctionPoint> saw;  // more than 16 pieces: classified through the entries
    for (int k = 0; k <= 20; ++k) saw.push_back({float(k) / 20.f, float(k % 2)});
    std::vector<TransferFunction::ColorPoint> greys = {{0.f, glm::vec3(0.1f)}, {0.3f, glm::vec3(0.7f)}, {1.f, glm::vec3(0.2f)}};
    const ClassificationTable entries = TransferFunction::fromPoints("g", greys, saw).bake(-2.f, 5.f, 1.0);
    ASSERT_EQ(entries.pieces().count, 0);
    EXPECT_TRUE(entries.grey());
    const ClassificationTable pieces = TransferFunction::fromPoints("g", greys, {{0.f, 0.f}, {1.f, 1.f}}).bake(-2.f, 5.f, 1.0);
    ASSERT_GT(pieces.pieces().count, 0);
    EXPECT_TRUE(pieces.grey());
    for (const bool manyPieces : {false, true}) {
        auto tinted = greys;
        tinted[1].rgb.z = std::nextafter(0.7f, 1.f);  // one ulp of blue at one point
        const auto sigma = manyPieces ? saw : std::vector<TransferFunction::ExtinctionPoint>{{0.f, 0.f}, {1.f, 1.f}};
        EXPECT_FALSE(TransferFunction::fromPoints("t", tinted, sigma).bake(-2.f, 5.f, 1.0).grey()) << manyPieces;
    }
    EXPECT_TRUE(ClassificationTable().grey());  // empty: nothing is drawn
}

TEST(TransferFunctionBake, BothEndsOfTheRangeMapExactly) {
    const float lo = -3.f, hi = 7.f;
    const TransferFunction tf = TransferFunction::preset("ct-bone");
    const ClassificationTable table = tf.bake(lo, hi, 1.0);
    EXPECT_NEAR(table.indexOf(lo), 0.f, 1e-3f);
    EXPECT_NEAR(table.indexOf(hi), float(ClassificationTable::kSize - 1), 1e-3f);
    expectSame(table(lo), tf.evaluate(0.f), 1e-6f);
    expectSame(table(hi), tf.evaluate(1.f), 1e-6f);
    expectSame(table(lo - 100.f), tf.evaluate(0.f), 0.f);  // clamped below
    expectSame(table(hi + 100.f), tf.evaluate(1.f), 0.f);  // clamped above
    // The value in the middle of the range is x = 0.5.
    expectSame(table(0.5f * (lo + hi)), tf.evaluate(0.5f), 1e-4f);
}

TEST(TransferFunctionBake, OneValuedGridMapsToTheTopOfTheFunction) {
    const TransferFunction grey = TransferFunction::preset("grey");
    const ClassificationTable table = grey.bake(2.f, 2.f, 1.0);
    EXPECT_FLOAT_EQ(table(2.f).sigma, 0.5f);
    EXPECT_FALSE(table.empty());
    const auto zero = TransferFunction::fromPoints("z", {{0.f, glm::vec3(1.f)}}, {{0.f, 0.f}});
    EXPECT_TRUE(zero.bake(0.f, 1.f, 1.0).empty());
    EXPECT_TRUE(ClassificationTable().empty());
    EXPECT_EQ(ClassificationTable()(0.5f).sigma, 0.f);
}

// --- JSON -----------------------------------------------------------------------

TEST(TransferFunctionJson, ToJsonRoundTrips) {
    for (const auto& name : TransferFunction::presetNames()) {
        const TransferFunction tf = TransferFunction::preset(name);
        const std::string text = tf.toJson();
        EXPECT_EQ(text.find('\n'), std::string::npos);
        const auto j = nlohmann::json::parse(text);
        EXPECT_EQ(j.at("name"), name);
        EXPECT_EQ(j.at("units"), "voxel");
        EXPECT_EQ(j.at("color").size(), tf.colors().size());
        EXPECT_EQ(j.at("extinction").size(), tf.extinction().size());
        const TransferFunction back = TransferFunction::fromJson(text, "<toJson>");
        for (float x = 0.f; x <= 1.f; x += 1.f / 97) expectSame(back.evaluate(x), tf.evaluate(x), 0.f);
    }
    // Short numbers stay short (no widened-float noise such as 0.10000000149011612).
    const std::string ct = TransferFunction::preset("ct-bone").toJson();
    EXPECT_NE(ct.find("[0.12,0.3,0.06,0.04]"), std::string::npos) << ct;
    EXPECT_EQ(ct.find("0.1199"), std::string::npos) << ct;
}

TEST(TransferFunctionJson, ReadsTheVdbsplatFormat) {
    TempDir dir;
    const std::string path = dir.write("tissue.json", R"({
        "name": "tissue", "units": "world",
        "color": [[0, 0, 0, 0], [0.5, 1, 0.5, 0], [1, 1, 1, 1]],
        "extinction": [[0.2, 0], [1, 4]]
    })");
    const TransferFunction tf = TransferFunction::fromSpec(path);
    EXPECT_EQ(tf.name(), "tissue");
    EXPECT_TRUE(tf.worldUnits());
    EXPECT_EQ(tf.evaluate(0.25f).color, glm::vec3(0.5f, 0.25f, 0.f));
    EXPECT_FLOAT_EQ(tf.evaluate(0.6f).sigma, 2.f);
    EXPECT_FLOAT_EQ(tf.evaluate(0.1f).sigma, 0.f);  // constant before the first point
    EXPECT_FLOAT_EQ(tf.bake(0.f, 1.f, 0.5)(1.f).sigma, 2.f);
    EXPECT_NE(tf.toJson().find("\"units\":\"world\""), std::string::npos);
}

TEST(TransferFunctionJson, DefaultsAndSrgbColours) {
    TempDir dir;
    const std::string path = dir.write("my-map.json", R"({"colorspace": "srgb",
        "color": [[0, 0.5, 0.5, 0.5]], "extinction": [[0, 1]]})");
    const TransferFunction tf = TransferFunction::fromSpec(path);
    EXPECT_EQ(tf.name(), "my-map");  // the file's stem
    EXPECT_FALSE(tf.worldUnits());
    EXPECT_FLOAT_EQ(tf.evaluate(0.7f).color.x, srgbToLinear(0.5f));
}

TEST(TransferFunctionJson, StepsAtEqualX) {
    const TransferFunction tf = TransferFunction::fromJson(
        R"({"color": [[0, 0, 0, 0], [1, 1, 1, 1]], "extinction": [[0, 0], [0.5, 0], [0.5, 1], [1, 1]]})", "step");
    EXPECT_FLOAT_EQ(tf.evaluate(0.49f).sigma, 0.f);
    EXPECT_FLOAT_EQ(tf.evaluate(0.5f).sigma, 1.f);  // the later point wins at the jump
    EXPECT_FLOAT_EQ(tf.evaluate(0.51f).sigma, 1.f);
}

// --- ParaView colour maps -----------------------------------------------------------

TEST(TransferFunctionParaView, RgbPointsAreRescaledAndDecodedFromSrgb) {
    TempDir dir;
    const std::string path = dir.write("pv.json", R"([{
        "ColorSpace": "Diverging", "Name": "Cool to Warm", "NanColor": [1, 1, 0],
        "RGBPoints": [-100, 0, 0, 1,  100, 0.5, 0.5, 0.5,  300, 1, 0, 0]
    }])");
    const TransferFunction tf = TransferFunction::fromSpec(path);
    EXPECT_EQ(tf.name(), "Cool to Warm");
    ASSERT_EQ(tf.colors().size(), 3u);
    EXPECT_FLOAT_EQ(tf.colors()[1].x, 0.5f);  // 100 in [-100, 300]
    EXPECT_FLOAT_EQ(tf.colors()[2].x, 1.f);
    EXPECT_FLOAT_EQ(tf.evaluate(0.5f).color.x, srgbToLinear(0.5f));
    EXPECT_EQ(tf.evaluate(0.f).color, glm::vec3(0.f, 0.f, 1.f));
    // No "Points": the default ramp (the grey preset's extinction).
    EXPECT_FLOAT_EQ(tf.evaluate(1.f).sigma, TransferFunction::preset("grey").evaluate(1.f).sigma);
    EXPECT_FLOAT_EQ(tf.evaluate(0.5f).sigma, TransferFunction::preset("grey").evaluate(0.5f).sigma);
}

TEST(TransferFunctionParaView, OpacityPointsBecomeExtinction) {
    const TransferFunction tf = TransferFunction::fromJson(R"({
        "RGBPoints": [0, 0, 0, 0,  255, 1, 1, 1],
        "Points": [0, 0, 0.5, 0,  127.5, 0.5, 0.5, 0,  255, 1, 0.5, 0]
    })", "object.json");
    EXPECT_FLOAT_EQ(tf.evaluate(0.f).sigma, 0.f);
    EXPECT_NEAR(tf.evaluate(0.5f).sigma, std::log(2.f), 1e-6f);           // α = 0.5 → σ = ln 2 per voxel
    EXPECT_NEAR(tf.evaluate(1.f).sigma, -std::log(1.f - 0.999f), 1e-4f);  // α = 1 capped at 0.999
}

TEST(TransferFunctionParaView, OpacityOutsideTheColourRangeIsClipped) {
    // Opacity points span [-10, 10]; the colour map spans [0, 10]: x = 0 gets the interpolated opacity.
    const TransferFunction tf = TransferFunction::fromJson(R"({
        "RGBPoints": [0, 1, 1, 1,  10, 1, 1, 1],
        "Points": [-10, 0, 0.5, 0,  10, 0.5, 0.5, 0]
    })", "clip.json");
    EXPECT_NEAR(tf.evaluate(0.f).sigma, -std::log(1.f - 0.25f), 1e-6f);
    EXPECT_NEAR(tf.evaluate(1.f).sigma, std::log(2.f), 1e-6f);
}

TEST(TransferFunctionParaView, MidpointAddsAHalfOpacityPoint) {
    const TransferFunction tf = TransferFunction::fromJson(R"({
        "RGBPoints": [0, 1, 1, 1,  1, 1, 1, 1],
        "Points": [0, 0, 0.25, 0,  1, 0.5, 0.5, 0]
    })", "mid.json");
    EXPECT_NEAR(tf.evaluate(0.25f).sigma, -std::log(1.f - 0.25f), 1e-6f);
}

// --- Invalid files ------------------------------------------------------------------

struct BadFile {
    const char* name;
    const char* text;
    const char* reason;
};

TEST(TransferFunctionInvalid, EveryKindOfBadFileNamesTheFileAndTheReason) {
    const BadFile cases[] = {
        {"syntax.json", "{\"color\": [[0, 0, 0, 0]]\n  \"extinction\": }", "not valid JSON at line 2, column 14: syntax error while parsing object - unexpected string literal"},
        {"empty.json", "", "not valid JSON at line 1, column 1"},
        {"nan.json", R"({"color": [[0, NaN, 0, 0]], "extinction": [[0, 1]]})", "not valid JSON"},
        {"overflow.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[0, 1e999]]})", "number overflow"},
        {"float-range.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[0, 1e39]]})", "not finite or out of range"},
        {"no-color.json", R"({"extinction": [[0, 1]]})", "missing 'color' array"},
        {"no-extinction.json", R"({"color": [[0, 0, 0, 0]]})", "missing 'extinction' array"},
        {"neither.json", R"({"colours": []})", "neither a vdbsplat transfer function"},
        {"not-array.json", R"({"color": 3, "extinction": [[0, 1]]})", "'color' must be an array"},
        {"empty-color.json", R"({"color": [], "extinction": [[0, 1]]})", "'color' has no points"},
        {"empty-ext.json", R"({"color": [[0, 0, 0, 0]], "extinction": []})", "'extinction' has no points"},
        {"tuple-color.json", R"({"color": [[0, 1, 1]], "extinction": [[0, 1]]})", "color[0]: expected [x, r, g, b]"},
        {"tuple-ext.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[0, 1, 2]]})", "extinction[0]: expected [x, sigma]"},
        {"string.json", R"({"color": [[0, "red", 0, 0]], "extinction": [[0, 1]]})", "color[0]: expected a number"},
        {"order.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[0, 0], [0.6, 1], [0.4, 1]]})",
         "extinction[2]: x = 0.4 is less than the previous x = 0.6"},
        {"x-range.json", R"({"color": [[0, 0, 0, 0], [1.5, 1, 1, 1]], "extinction": [[0, 1]]})",
         "color[1]: x = 1.5 is outside [0, 1]"},
        {"x-negative.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[-0.1, 1]]})", "x = -0.1 is outside [0, 1]"},
        {"negative.json", R"({"color": [[0, 0, 0, 0]], "extinction": [[0, -0.5]]})", "sigma = -0.5 is negative"},
        {"bright.json", R"({"color": [[0, 1.2, 0, 0]], "extinction": [[0, 1]]})", "component 1.2 is outside [0, 1]"},
        {"units.json", R"({"units": "metres", "color": [[0, 0, 0, 0]], "extinction": [[0, 1]]})", "'units' must be"},
        {"space.json", R"({"colorspace": "lab", "color": [[0, 0, 0, 0]], "extinction": [[0, 1]]})",
         "'colorspace' must be"},
        {"name.json", R"({"name": 3, "color": [[0, 0, 0, 0]], "extinction": [[0, 1]]})", "'name' must be a string"},
        {"typo.json", R"({"colour": 1, "color": [[0, 0, 0, 0]], "extinction": [[0, 1]]})", "unknown key 'colour'"},
        {"scalar.json", "42", "expected a JSON object"},
        {"two-maps.json", R"([{"RGBPoints": [0, 0, 0, 0]}, {"RGBPoints": [0, 0, 0, 0]}])", "exactly one"},
        {"array-no-rgb.json", R"([{"Name": "x"}])", "no 'RGBPoints'"},
        {"pv-count.json", R"({"RGBPoints": [0, 0, 0, 0, 1, 1, 1]})", "not a multiple of 4"},
        {"pv-empty.json", R"({"RGBPoints": []})", "'RGBPoints' has no points"},
        {"pv-flat.json", R"({"RGBPoints": [[0], 0, 0, 0]})", "RGBPoints[0]: expected a number"},
        {"pv-order.json", R"({"RGBPoints": [1, 0, 0, 0, 0, 1, 1, 1]})", "x must not decrease"},
        {"pv-span.json", R"({"RGBPoints": [5, 0, 0, 0, 5, 1, 1, 1]})", "span no range"},
        {"pv-colour.json", R"({"RGBPoints": [0, 0, 0, 0, 1, 2, 1, 1]})", "component 2 is outside [0, 1]"},
        {"pv-opacity.json", R"({"RGBPoints": [0, 0, 0, 0, 1, 1, 1, 1], "Points": [0, 1.5, 0.5, 0]})",
         "opacity = 1.5 is outside [0, 1]"},
        {"pv-points.json", R"({"RGBPoints": [0, 0, 0, 0, 1, 1, 1, 1], "Points": [0, 1, 0.5]})",
         "'Points' has 3 numbers"},
    };
    TempDir dir;
    for (const BadFile& c : cases) {
        const std::string path = dir.write(c.name, c.text);
        const std::string msg = errorOf([&] { TransferFunction::fromSpec(path); });
        EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << c.name << ": message does not start with the file: " << msg;
        EXPECT_NE(msg.find(c.reason), std::string::npos) << c.name << ": got '" << msg << "'";
        EXPECT_EQ(msg.find('\n'), std::string::npos) << c.name << ": not one line: " << msg;
    }
}

TEST(TransferFunctionInvalid, HugeFileIsRefusedBeforeParsing) {
    TempDir dir;
    const std::string path = dir.path() + "/huge.json";
    {
        std::ofstream out(path, std::ios::binary);
        out << "{\"color\": [[0, 0, 0, 0]], \"extinction\": [[0, 1]]}";
        out << std::string(TransferFunction::kMaxFileBytes, ' ');
    }
    const std::string msg = errorOf([&] { TransferFunction::fromSpec(path); });
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find("limited to 16 MiB"), std::string::npos) << msg;
}

// 30 000–100 000 levels of nesting overflowed the stack (json::dump in the message; issue 12).
TEST(TransferFunctionInvalid, DeepNestingIsRefusedBeforeParsing) {
    const std::string deep(100000, '['), close(100000, ']');
    const std::string texts[] = {
        deep + close,                                             // bare arrays
        "{\"color\": " + deep + close + "}",                       // inside the vdbsplat form
        "{\"RGBPoints\": " + deep + "0" + close + "}",             // ParaView form, a number inside
        "[" + std::string(100000, '{') + std::string(100000, '}') + "]",  // objects (invalid, but deep first)
    };
    for (const std::string& text : texts) {
        const std::string msg = errorOf([&] { TransferFunction::fromJson(text, "deep.json"); });
        EXPECT_NE(msg.find("deep.json"), std::string::npos) << msg.substr(0, 200);
        EXPECT_NE(msg.find("nested deeper than"), std::string::npos) << msg.substr(0, 200);
        EXPECT_LT(msg.size(), 200u);
    }
    // Brackets inside strings do not count; ordinary files are three levels deep.
    const std::string name = "{\"name\": \"" + deep + "\", \"color\": [[0, 1, 1, 1]], \"extinction\": [[0, 1]]}";
    EXPECT_EQ(TransferFunction::fromJson(name, "n.json").name(), deep);
}

// A wrong element that is a large array is described by its size, not dumped into the message.
TEST(TransferFunctionInvalid, MessagesNeverDumpLargeValues) {
    std::string big = "[";
    for (int i = 0; i < 100000; ++i) big += (i ? ",1" : "1");
    big += "]";
    const std::string msg = errorOf(
        [&] { TransferFunction::fromJson("{\"color\": [" + big + "], \"extinction\": [[0, 1]]}", "big.json"); });
    EXPECT_NE(msg.find("an array of 100000 elements"), std::string::npos) << msg.substr(0, 300);
    EXPECT_LT(msg.size(), 300u);
}

TEST(TransferFunctionInvalid, FolderIsNotAFile) {
    TempDir dir;
    const std::string msg = errorOf([&] { TransferFunction::fromSpec(dir.path()); });
    EXPECT_EQ(msg, dir.path() + ": not a regular file");
}

TEST(TransferFunctionInvalid, FromPointsValidates) {
    EXPECT_NE(errorOf([] { TransferFunction::fromPoints("p", {}, {{0.f, 1.f}}); }).find("p: 'color' has no points"),
              std::string::npos);
    EXPECT_NE(errorOf([] { TransferFunction::fromPoints("p", {{0.f, glm::vec3(0.f)}}, {{0.f, NAN}}); })
                  .find("sigma is not finite"),
              std::string::npos);
    EXPECT_NE(errorOf([] { TransferFunction::fromPoints("p", {{NAN, glm::vec3(0.f)}}, {{0.f, 1.f}}); })
                  .find("x is not a finite number"),
              std::string::npos);
}

}  // namespace
}  // namespace vdbsplat
