// volume/transfer_function.cpp — piecewise-linear transfer functions, presets,
// the vdbsplat JSON format, ParaView colour maps, and the baked table.
// Owns: every rule a transfer-function file must satisfy (docs/transfer-functions.md)
// and the preset values (their reasons are beside them).
#include "volume/transfer_function.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "image/image.h"
#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat {

namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

/// ParaView opacities are capped below 1 before σ = −ln(1 − α): α = 0.999 → σ ≈ 6.9 per voxel.
constexpr float kMaxParaViewOpacity = 0.999f;

// --- Small helpers -----------------------------------------------------------

/// Keeps a message on one line: control characters become spaces, long text is cut.
std::string oneLine(std::string s, size_t maxLength = 160) {
    for (char& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
    if (s.size() > maxLength) s = s.substr(0, maxLength) + "...";
    return s;
}

/// Shortest decimal text that reads back as the same float.
std::string shortest(float v) {
    char buf[32];
    const auto result = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, result.ptr);
}

/// A float as a double that prints in the float's shortest form (not as the widened value).
double jsonNumber(float v) {
    const std::string text = shortest(v);
    double d = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), d);
    return d;
}

std::string fail(const std::string& origin, const std::string& what) { return origin + ": " + what; }

/// Deepest array/object nesting a transfer-function file may use (the formats need 3).
constexpr int kMaxJsonDepth = 64;

/// A short text of @p v for a message: scalars and small containers as JSON, cut to
/// @p maxLength; a large container only by its size (never dumps unbounded JSON).
std::string preview(const nlohmann::json& v, size_t maxLength) {
    if (v.is_structured() && v.size() > 16)
        return std::string(v.is_array() ? "an array" : "an object") + " of " + std::to_string(v.size()) + " elements";
    return oneLine(v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), maxLength);
}

std::string positionOf(const std::string& text, size_t byte);

/// Refuses JSON nested deeper than kMaxJsonDepth before it is parsed (a file of 100 000
/// '[' would otherwise exhaust the stack in the parser or in dump()). Strings are skipped,
/// so brackets inside them do not count.
void checkNesting(const std::string& text, const std::string& origin) {
    const size_t at = jsonNestingPastLimit(text, kMaxJsonDepth);
    if (at != std::string::npos)
        throw Error(fail(origin, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels at " +
                                     positionOf(text, at + 1) + " (transfer functions need 3)"));
}

// --- Piecewise-linear evaluation --------------------------------------------

/// The points {x, value} (x non-decreasing) around @p x: the last with p.x ≤ x and the first
/// with p.x > x (so at a jump, two equal x, the later point is the first); null past an end.
template <typename Point>
std::pair<const Point*, const Point*> around(const std::vector<Point>& points, double x) {
    const auto upper = std::upper_bound(points.begin(), points.end(), x, [](double v, const Point& p) { return v < p.x; });
    return {upper == points.begin() ? nullptr : &*(upper - 1), upper == points.end() ? nullptr : &*upper};
}

/// Evaluates points {x, value} (x non-decreasing) at @p x: linear between points,
/// constant beyond the ends; at a jump (two equal x) the later point wins.
template <typename Point, typename Get>
auto piecewise(const std::vector<Point>& points, float x, Get get) -> decltype(get(points.front())) {
    const auto [a, b] = around(points, x);
    if (!a || !b) return get(a ? *a : *b);
    const float t = (x - a->x) / (b->x - a->x);  // b.x > a.x: upper_bound skipped equal x
    return get(*a) + t * (get(*b) - get(*a));
}

/// On [lo, next point): the function's value at lo and its slope per unit x, in double, as
/// piecewise() (right-continuous at a jump, constant beyond the ends).
template <class Point, class Get>
std::pair<double, double> lineOn(const std::vector<Point>& points, double lo, Get get) {
    const auto [a, b] = around(points, lo);
    if (!a || !b) return {get(a ? *a : *b), 0.0};
    const double slope = (double(get(*b)) - double(get(*a))) / (double(b->x) - double(a->x));
    return {double(get(*a)) + slope * (lo - double(a->x)), slope};
}

// --- Validation (shared by files, ParaView maps and fromPoints) -------------

void checkX(float x, float previous, size_t i, const std::string& list, const std::string& origin) {
    const std::string where = list + "[" + std::to_string(i) + "]";
    if (!std::isfinite(x)) throw Error(fail(origin, where + ": x is not a finite number"));
    if (x < 0.f || x > 1.f) throw Error(fail(origin, where + ": x = " + shortest(x) + " is outside [0, 1]"));
    if (i > 0 && x < previous)
        throw Error(fail(origin, where + ": x = " + shortest(x) + " is less than the previous x = " +
                                     shortest(previous) + " (x must not decrease)"));
}

void validateColors(const std::vector<TransferFunction::ColorPoint>& points, const std::string& origin) {
    if (points.empty()) throw Error(fail(origin, "'color' has no points"));
    for (size_t i = 0; i < points.size(); ++i) {
        checkX(points[i].x, i ? points[i - 1].x : 0.f, i, "color", origin);
        for (int c = 0; c < 3; ++c) {
            const float v = points[i].rgb[c];
            if (!std::isfinite(v) || v < 0.f || v > 1.f)
                throw Error(fail(origin, "color[" + std::to_string(i) + "]: component " + shortest(v) +
                                             " is outside [0, 1]"));
        }
    }
}

void validateExtinction(const std::vector<TransferFunction::ExtinctionPoint>& points, const std::string& origin) {
    if (points.empty()) throw Error(fail(origin, "'extinction' has no points"));
    for (size_t i = 0; i < points.size(); ++i) {
        checkX(points[i].x, i ? points[i - 1].x : 0.f, i, "extinction", origin);
        const float s = points[i].sigma;
        if (!std::isfinite(s)) throw Error(fail(origin, "extinction[" + std::to_string(i) + "]: sigma is not finite"));
        if (s < 0.f)
            throw Error(fail(origin, "extinction[" + std::to_string(i) + "]: sigma = " + shortest(s) + " is negative"));
    }
}

// --- JSON reading -------------------------------------------------------------

/// A finite JSON number that fits a float; @p where names it in the error.
float number(const json& v, const std::string& where, const std::string& origin) {
    if (!v.is_number()) throw Error(fail(origin, where + ": expected a number, got " + preview(v, 40)));
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > double(std::numeric_limits<float>::max()))
        throw Error(fail(origin, where + ": number is not finite or out of range"));
    return float(d);
}

/// An array of fixed-size number tuples, e.g. [[x, r, g, b], …].
std::vector<std::vector<float>> tuples(const json& obj, const std::string& key, size_t size,
                                       const std::string& shape, const std::string& origin) {
    if (!obj.contains(key)) throw Error(fail(origin, "missing '" + key + "' array of " + shape));
    const json& list = obj.at(key);
    if (!list.is_array()) throw Error(fail(origin, "'" + key + "' must be an array of " + shape));
    if (list.empty()) throw Error(fail(origin, "'" + key + "' has no points"));
    std::vector<std::vector<float>> out;
    out.reserve(list.size());
    for (size_t i = 0; i < list.size(); ++i) {
        const std::string where = key + "[" + std::to_string(i) + "]";
        if (!list[i].is_array() || list[i].size() != size)
            throw Error(fail(origin, where + ": expected " + shape + ", got " + preview(list[i], 60)));
        std::vector<float> t(size);
        for (size_t k = 0; k < size; ++k) t[k] = number(list[i][k], where, origin);
        out.push_back(std::move(t));
    }
    return out;
}

/// A flat ParaView number array ("RGBPoints", "Points") whose length is a multiple of 4.
std::vector<float> flatQuads(const json& obj, const std::string& key, const std::string& origin) {
    const json& list = obj.at(key);
    if (!list.is_array()) throw Error(fail(origin, "'" + key + "' must be a flat array of numbers"));
    if (list.empty()) throw Error(fail(origin, "'" + key + "' has no points"));
    if (list.size() % 4 != 0)
        throw Error(fail(origin, "'" + key + "' has " + std::to_string(list.size()) +
                                     " numbers, not a multiple of 4 (x, and three values per point)"));
    std::vector<float> out(list.size());
    for (size_t i = 0; i < list.size(); ++i) out[i] = number(list[i], key + "[" + std::to_string(i) + "]", origin);
    for (size_t i = 4; i < out.size(); i += 4)
        if (out[i] < out[i - 4])
            throw Error(fail(origin, "'" + key + "' point " + std::to_string(i / 4) + ": x = " + shortest(out[i]) +
                                         " is less than the previous x = " + shortest(out[i - 4]) +
                                         " (x must not decrease)"));
    return out;
}

std::string optionalString(const json& obj, const std::string& key, const std::string& fallback,
                           const std::string& origin) {
    if (!obj.contains(key)) return fallback;
    if (!obj.at(key).is_string()) throw Error(fail(origin, "'" + key + "' must be a string"));
    return obj.at(key).get<std::string>();
}

std::string defaultName(const std::string& origin) {
    const std::string stem = fs::path(origin).stem().string();
    return stem.empty() ? origin : stem;
}

/// The vdbsplat format: {"name", "units", "colorspace", "color": [[x,r,g,b]…], "extinction": [[x,σ]…]}.
TransferFunction parseVdbsplat(const json& obj, const std::string& origin) {
    const auto colorTuples = tuples(obj, "color", 4, "[x, r, g, b] points", origin);
    const auto sigmaTuples = tuples(obj, "extinction", 2, "[x, sigma] points", origin);
    static const char* kKeys[] = {"name", "units", "colorspace", "color", "extinction", "description"};
    for (const auto& item : obj.items())
        if (std::find(std::begin(kKeys), std::end(kKeys), item.key()) == std::end(kKeys))
            throw Error(fail(origin, "unknown key '" + oneLine(item.key(), 40) +
                                         "' (expected name, units, colorspace, color, extinction, description)"));
    const std::string units = optionalString(obj, "units", "voxel", origin);
    if (units != "voxel" && units != "world")
        throw Error(fail(origin, "'units' must be \"voxel\" or \"world\", got '" + oneLine(units, 40) + "'"));
    const std::string space = optionalString(obj, "colorspace", "linear", origin);
    if (space != "linear" && space != "srgb")
        throw Error(fail(origin, "'colorspace' must be \"linear\" or \"srgb\", got '" + oneLine(space, 40) + "'"));
    optionalString(obj, "description", "", origin);

    std::vector<TransferFunction::ColorPoint> colors;
    for (const auto& t : colorTuples) colors.push_back({t[0], glm::vec3(t[1], t[2], t[3])});
    validateColors(colors, origin);  // before sRGB decoding, so out-of-range values are named as written
    if (space == "srgb")
        for (auto& c : colors) c.rgb = glm::vec3(srgbToLinear(c.rgb.x), srgbToLinear(c.rgb.y), srgbToLinear(c.rgb.z));
    std::vector<TransferFunction::ExtinctionPoint> sigmas;
    for (const auto& t : sigmaTuples) sigmas.push_back({t[0], t[1]});
    validateExtinction(sigmas, origin);
    return TransferFunction::fromPoints(optionalString(obj, "name", defaultName(origin), origin), std::move(colors),
                                        std::move(sigmas), units == "world");
}

/// Maps x from [lo, hi] to [0, 1]; a zero-width range maps to 0.
float rescale(float x, float lo, float hi) { return hi > lo ? (x - lo) / (hi - lo) : 0.f; }

/// Restricts points {x, value} (x non-decreasing, any range) to [0, 1]: the values at
/// 0 and 1 are interpolated, interior points kept.
std::vector<TransferFunction::ExtinctionPoint> clipToUnit(const std::vector<TransferFunction::ExtinctionPoint>& p) {
    const auto at = [&](float x) { return piecewise(p, x, [](const auto& q) { return q.sigma; }); };
    std::vector<TransferFunction::ExtinctionPoint> out{{0.f, at(0.f)}};
    for (const auto& q : p)
        if (q.x > 0.f && q.x < 1.f) out.push_back(q);
    out.push_back({1.f, at(1.f)});
    return out;
}

/// ParaView "Points" [x, opacity, midpoint, sharpness, …] → extinction per voxel:
/// x rescaled with the colour map's range, a midpoint ≠ 0.5 becomes an extra point
/// at half opacity, sharpness is ignored (linear), and σ = −ln(1 − min(α, 0.999)).
std::vector<TransferFunction::ExtinctionPoint> paraViewOpacity(const std::vector<float>& q, float lo, float hi,
                                                               const std::string& origin) {
    std::vector<TransferFunction::ExtinctionPoint> alpha;
    for (size_t i = 0; i < q.size(); i += 4) {
        const std::string where = "'Points' point " + std::to_string(i / 4);
        for (int k = 1; k < 4; ++k)
            if (q[i + k] < 0.f || q[i + k] > 1.f)
                throw Error(fail(origin, where + ": " + (k == 1 ? "opacity" : k == 2 ? "midpoint" : "sharpness") +
                                             " = " + shortest(q[i + k]) + " is outside [0, 1]"));
        const float x = rescale(q[i], lo, hi);
        alpha.push_back({x, q[i + 1]});
        const bool last = i + 4 >= q.size();
        if (!last && q[i + 2] != 0.5f && q[i + 4] > q[i]) {
            const float xn = rescale(q[i + 4], lo, hi);
            alpha.push_back({x + q[i + 2] * (xn - x), 0.5f * (q[i + 1] + q[i + 5])});
        }
    }
    auto clipped = clipToUnit(alpha);
    for (auto& p : clipped) p.sigma = -std::log(1.f - std::min(p.sigma, kMaxParaViewOpacity));
    return clipped;
}

/// A ParaView colour map: {"Name", "RGBPoints": [x, r, g, b, …], optional "Points"}.
TransferFunction parseParaView(const json& obj, const std::string& origin) {
    const std::vector<float> rgb = flatQuads(obj, "RGBPoints", origin);
    const float lo = rgb.front(), hi = rgb[rgb.size() - 4];
    if (rgb.size() > 4 && !(hi > lo))
        throw Error(fail(origin, "'RGBPoints' span no range (first and last x are both " + shortest(lo) + ")"));
    std::vector<TransferFunction::ColorPoint> colors;
    for (size_t i = 0; i < rgb.size(); i += 4) {
        for (int c = 1; c < 4; ++c)
            if (rgb[i + c] < 0.f || rgb[i + c] > 1.f)
                throw Error(fail(origin, "'RGBPoints' point " + std::to_string(i / 4) + ": component " +
                                             shortest(rgb[i + c]) + " is outside [0, 1]"));
        // ParaView colours are display (sRGB-encoded) values; vdbsplat emits linear RGB.
        colors.push_back({rescale(rgb[i], lo, hi),
                          glm::vec3(srgbToLinear(rgb[i + 1]), srgbToLinear(rgb[i + 2]), srgbToLinear(rgb[i + 3]))});
    }
    std::vector<TransferFunction::ExtinctionPoint> sigmas = TransferFunction::preset("grey").extinction();
    if (obj.contains("Points")) sigmas = paraViewOpacity(flatQuads(obj, "Points", origin), lo, hi, origin);
    validateColors(colors, origin);
    validateExtinction(sigmas, origin);
    return TransferFunction::fromPoints(optionalString(obj, "Name", defaultName(origin), origin), std::move(colors),
                                        std::move(sigmas), false);
}

/// "line L, column C" of byte offset @p byte (1-based, as nlohmann reports it) in @p text.
std::string positionOf(const std::string& text, size_t byte) {
    size_t line = 1, column = 1;
    for (size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
        if (text[i] == '\n') { ++line; column = 1; } else { ++column; }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

/// nlohmann's parse error without its "[json.exception…] parse error at …: " prefix.
std::string parseReason(const std::string& what) {
    const size_t column = what.find("column ");
    const size_t colon = what.find(": ", column == std::string::npos ? 0 : column);
    return oneLine(colon == std::string::npos ? what : what.substr(colon + 2));
}

json parseJsonText(const std::string& text, const std::string& origin) {
    checkNesting(text, origin);
    try {
        return json::parse(text);
    } catch (const json::parse_error& e) {
        throw Error(fail(origin, "not valid JSON at " + positionOf(text, e.byte) + ": " + parseReason(e.what())));
    } catch (const json::exception& e) {  // e.g. out_of_range 406: a number overflowing a double
        const std::string what = e.what();
        const size_t end = what.find("] ");
        throw Error(fail(origin, "not valid JSON: " + oneLine(end == std::string::npos ? what : what.substr(end + 2))));
    }
}

std::string readSmallFile(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(fail(path, "not a regular file"));
    const auto size = fs::file_size(path, ec);
    if (ec) throw Error(fail(path, "cannot read: " + ec.message()));
    if (size > TransferFunction::kMaxFileBytes)
        throw Error(fail(path, "file is " + std::to_string(size) + " bytes; transfer-function files are limited to " +
                                   std::to_string(TransferFunction::kMaxFileBytes >> 20) + " MiB"));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(fail(path, std::string("cannot read: ") + std::strerror(errno)));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw Error(fail(path, "read failed"));
    return text.str();
}

// --- Presets -----------------------------------------------------------------
// Colours are linear RGB (what the renderer emits; PNGs are sRGB-encoded on
// output). Extinction is per voxel length. Emission–absorption has no shading,
// so a region only shows structure while it is translucent: the magnitudes keep
// the typical path through the main material at a few optical depths.

/// Grey: colour = x, σ = 0.5·x per voxel (a 2-voxel-thick x = 1 layer has τ = 1).
TransferFunction greyPreset() {
    return TransferFunction::fromPoints("grey", {{0.f, glm::vec3(0.f)}, {1.f, glm::vec3(1.f)}},
                                        {{0.f, 0.f}, {1.f, 0.5f}});
}

/// CT bone/tissue, tuned on the Engine and Bonsai CTs (uint8 → [0, 1]; histograms in
/// docs/transfer-functions.md): x < 0.12 air and scanner noise (σ = 0); 0.12–0.35 soft
/// tissue / leaves / partial-volume edges, faint reddish (σ ≤ 0.008); 0.35–0.62 bone / the
/// engine block (the Engine's main peak is 0.50–0.62), tan to ivory, σ rising to 0.03 so a
/// 100-voxel path through the block is τ ≈ 3 (translucent, not a flat silhouette);
/// 0.62–1 dense bone / metal inserts / the Bonsai's pot, near white, σ 0.2–0.4 (opaque
/// within a few voxels, so they read as solid parts inside the translucent block).
TransferFunction ctBonePreset() {
    return TransferFunction::fromPoints("ct-bone",
                                        {{0.00f, {0.00f, 0.00f, 0.00f}},
                                         {0.12f, {0.30f, 0.06f, 0.04f}},
                                         {0.25f, {0.75f, 0.28f, 0.16f}},
                                         {0.45f, {0.90f, 0.55f, 0.35f}},
                                         {0.62f, {0.95f, 0.80f, 0.62f}},
                                         {0.75f, {1.00f, 0.95f, 0.90f}},
                                         {1.00f, {1.00f, 1.00f, 1.00f}}},
                                        {{0.00f, 0.000f},
                                         {0.12f, 0.000f},
                                         {0.20f, 0.003f},
                                         {0.35f, 0.008f},
                                         {0.50f, 0.020f},
                                         {0.62f, 0.030f},
                                         {0.75f, 0.200f},
                                         {1.00f, 0.400f}});
}

/// Fire for clouds: dark red → orange → yellow-white as density rises; σ from 0 at
/// the thinnest edge to 0.2 per voxel in the cores, so wisps stay translucent.
TransferFunction firePreset() {
    return TransferFunction::fromPoints("fire",
                                        {{0.00f, {0.10f, 0.00f, 0.00f}},
                                         {0.25f, {0.60f, 0.04f, 0.00f}},
                                         {0.50f, {1.00f, 0.28f, 0.02f}},
                                         {0.75f, {1.00f, 0.65f, 0.12f}},
                                         {1.00f, {1.00f, 0.95f, 0.75f}}},
                                        {{0.00f, 0.000f}, {0.20f, 0.010f}, {0.50f, 0.050f}, {1.00f, 0.200f}});
}

}  // namespace

// --- ClassificationTable -----------------------------------------------------

namespace {
/// Every entry's colour, and every piece's values and slopes, the same in r, g and b (bit for bit).
bool everyColorGrey(const std::vector<Classified>& entries, const LinearPieces& pieces) {
    for (int j = 0; j < pieces.count; ++j)
        if (!(pieces.value[0][j] == pieces.value[1][j] && pieces.value[0][j] == pieces.value[2][j] &&
              pieces.slope[0][j] == pieces.slope[1][j] && pieces.slope[0][j] == pieces.slope[2][j]))
            return false;
    return std::all_of(entries.begin(), entries.end(),
                       [](const Classified& c) { return c.color.x == c.color.y && c.color.x == c.color.z; });
}
}  // namespace

ClassificationTable::ClassificationTable(std::vector<Classified> entries, float valueMin, float valueMax,
                                         const LinearPieces& pieces)
    : entries_(std::move(entries)), pieces_(pieces) {
    if (valueMax > valueMin) {
        // Scale/offset in double so valueMin → 0 and valueMax → kSize − 1 as exactly as floats allow.
        const double scale = double(kSize - 1) / (double(valueMax) - double(valueMin));
        scale_ = float(scale);
        offset_ = float(-double(valueMin) * scale);
    } else {
        scale_ = 0.f;  // one-valued grid: everything is x = 1
        offset_ = float(kSize - 1);
    }
    if (!entries_.empty() && entries_.size() != size_t(kSize))
        throw Error("classification table: expected " + std::to_string(kSize) + " entries, got " +
                    std::to_string(entries_.size()));
    if (!pieces_.valid())
        throw Error("classification table: linear pieces must number 0.." + std::to_string(LinearPieces::kMax) +
                    ", start at index 0 with knots not decreasing below " + std::to_string(kSize - 1) +
                    ", and hold finite values and slopes");
    grey_ = everyColorGrey(entries_, pieces_);
    if (pieces_.count) {
        static_assert(LinearPieces::kMax * LinearPieces::kBucketWidth == kSize, "the buckets cover the table");
        pieces_.index();
        // Below the knot of the first piece with σ > 0 somewhere, σ = 0 + 0 · d exactly.
        const int j = pieces_.firstOpaque();
        transparentBelow_ = j == 0 ? -1.f : j == pieces_.count ? float(kSize - 1) : pieces_.knot[j];
        return;
    }
    // The first entry with σ > 0 (or kSize): below index first − 1 both lerped entries are 0.
    const auto first = std::find_if(entries_.begin(), entries_.end(), [](const Classified& c) { return !(c.sigma <= 0.f); });
    transparentBelow_ = float(std::distance(entries_.begin(), first)) - 1.f;
}

bool ClassificationTable::empty() const {
    if (entries_.empty()) return true;
    if (pieces_.count) return pieces_.firstOpaque() == pieces_.count;
    return std::none_of(entries_.begin(), entries_.end(), [](const Classified& c) { return c.sigma > 0.f; });
}

// --- TransferFunction ----------------------------------------------------------

TransferFunction TransferFunction::fromPoints(std::string name, std::vector<ColorPoint> colors,
                                              std::vector<ExtinctionPoint> extinction, bool worldUnits) {
    validateColors(colors, name);
    validateExtinction(extinction, name);
    TransferFunction tf;
    tf.name_ = std::move(name);
    tf.colors_ = std::move(colors);
    tf.extinction_ = std::move(extinction);
    tf.worldUnits_ = worldUnits;
    return tf;
}

std::vector<std::string> TransferFunction::presetNames() { return {"grey", "ct-bone", "fire"}; }

TransferFunction TransferFunction::preset(const std::string& name) {
    if (name == "grey") return greyPreset();
    if (name == "ct-bone") return ctBonePreset();
    if (name == "fire") return firePreset();
    throw Error("unknown transfer function preset '" + oneLine(name) + "' (choose grey, ct-bone, fire)");
}

TransferFunction TransferFunction::fromSpec(const std::string& spec) {
    const auto names = presetNames();
    if (std::find(names.begin(), names.end(), spec) != names.end()) return preset(spec);
    std::error_code ec;
    if (spec.empty() || !fs::exists(spec, ec))
        throw Error("unknown transfer function preset or file '" + oneLine(spec) + "' (presets: grey, ct-bone, fire)");
    return fromJson(readSmallFile(spec), spec);
}

TransferFunction TransferFunction::fromJson(const std::string& text, const std::string& origin) {
    if (text.size() > kMaxFileBytes)
        throw Error(fail(origin, "text is " + std::to_string(text.size()) +
                                     " bytes; transfer-function files are limited to 16 MiB"));
    const json doc = parseJsonText(text, origin);
    const json* obj = &doc;
    if (doc.is_array()) {
        if (doc.size() != 1 || !doc.front().is_object())
            throw Error(fail(origin, "a top-level array must hold exactly one ParaView colour map object, found " +
                                         std::to_string(doc.size()) + " elements"));
        obj = &doc.front();
        if (!obj->contains("RGBPoints")) throw Error(fail(origin, "ParaView colour map has no 'RGBPoints' array"));
    }
    if (!obj->is_object())
        throw Error(fail(origin, "expected a JSON object (vdbsplat transfer function) or a ParaView colour map"));
    if (obj->contains("RGBPoints")) return parseParaView(*obj, origin);
    if (!obj->contains("color") && !obj->contains("extinction"))
        throw Error(fail(origin, "neither a vdbsplat transfer function ('color' and 'extinction' arrays) "
                                 "nor a ParaView colour map ('RGBPoints')"));
    return parseVdbsplat(*obj, origin);
}

Classified TransferFunction::evaluate(float x) const {
    if (!std::isfinite(x) || colors_.empty() || extinction_.empty()) return {};
    x = std::clamp(x, 0.f, 1.f);
    return {piecewise(colors_, x, [](const ColorPoint& p) { return p.rgb; }),
            piecewise(extinction_, x, [](const ExtinctionPoint& p) { return p.sigma; })};
}

ClassificationTable TransferFunction::bake(float valueMin, float valueMax, double voxelSize) const {
    if (!std::isfinite(valueMin) || !std::isfinite(valueMax))
        throw Error("transfer function '" + name_ + "': value range is not finite");
    if (worldUnits_ && !(std::isfinite(voxelSize) && voxelSize > 0.0))
        throw Error("transfer function '" + name_ + "': world units need a positive voxel size");
    const float perVoxel = worldUnits_ ? float(voxelSize) : 1.f;  // σ·h: optical depth per voxel length
    std::vector<Classified> entries(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        entries[size_t(i)] = evaluate(float(double(i) / (ClassificationTable::kSize - 1)));
        entries[size_t(i)].sigma *= perVoxel;
    }
    return ClassificationTable(std::move(entries), valueMin, valueMax, pieces(perVoxel));
}

LinearPieces TransferFunction::pieces(float perVoxel) const {
    // Knots: every point's x inside (0, 1), colour and extinction alike; the pieces lie between.
    std::vector<float> knots{0.f};
    for (const auto& p : colors_) knots.push_back(p.x);
    for (const auto& p : extinction_) knots.push_back(p.x);
    std::sort(knots.begin(), knots.end());
    knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
    // The piece that ends at 1 reaches it; a step at 1 (two points there) needs one more piece
    // from 1 on, so that x = 1 takes the value after the step, as evaluate(1) does.
    const auto stepAtOne = [](const auto& points) {
        return std::count_if(points.begin(), points.end(), [](const auto& p) { return p.x >= 1.f; }) > 1;
    };
    if (knots.size() > 1 && knots.back() >= 1.f && !stepAtOne(colors_) && !stepAtOne(extinction_)) knots.pop_back();
    LinearPieces out;
    if (knots.size() > size_t(LinearPieces::kMax) || colors_.empty() || extinction_.empty()) return out;
    const double toIndex = ClassificationTable::kSize - 1;  // x = u · (kSize − 1)
    out.count = int(knots.size());
    for (int j = 0; j < out.count; ++j) {
        const double u = knots[size_t(j)];
        out.knot[j] = float(u * toIndex);
        for (int c = 0; c < 3; ++c) {
            const auto [value, slope] = lineOn(colors_, u, [c](const ColorPoint& p) { return p.rgb[c]; });
            out.value[c][j] = float(value), out.slope[c][j] = float(slope / toIndex);
        }
        const auto [value, slope] = lineOn(extinction_, u, [](const ExtinctionPoint& p) { return p.sigma; });
        out.value[3][j] = float(value * perVoxel), out.slope[3][j] = float(slope * perVoxel / toIndex);
    }
    // A slope past float's range (a huge σ over knots ulps apart) would make ∞ · 0: the table then.
    return out.valid() ? out : LinearPieces{};  // the ClassificationTable indexes it
}

bool LinearPieces::valid() const {
    if (count < 0 || count > kMax || (count > 0 && knot[0] != 0.f)) return false;
    for (int j = 0; j < count; ++j) {
        if (!(knot[j] >= (j ? knot[j - 1] : 0.f) && knot[j] <= float(ClassificationTable::kSize - 1))) return false;
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(value[c][j]) || !std::isfinite(slope[c][j])) return false;
    }
    return true;
}

void LinearPieces::index() {
    for (int j = 0; j < kMax; ++j) next[j] = j + 1 < count ? knot[j + 1] : std::numeric_limits<float>::infinity();
    knotsPerBucket = 0;
    for (int b = 0; b < kMax; ++b) {
        const float lo = float(b * kBucketWidth), hi = float((b + 1) * kBucketWidth);
        firstOfBucket[b] = 0;  // the knots after the first at or below lo
        for (int k = 1; k < count; ++k) firstOfBucket[b] += lo >= knot[k];
        int inside = 0;
        for (int k = 1; k < count; ++k) inside += knot[k] > lo && knot[k] < hi;
        knotsPerBucket = std::max(knotsPerBucket, inside);
    }
}

std::string TransferFunction::toJson() const {
    using ordered = nlohmann::ordered_json;
    ordered color = ordered::array(), sigma = ordered::array();
    for (const auto& p : colors_)
        color.push_back(ordered::array({jsonNumber(p.x), jsonNumber(p.rgb.x), jsonNumber(p.rgb.y), jsonNumber(p.rgb.z)}));
    for (const auto& p : extinction_) sigma.push_back(ordered::array({jsonNumber(p.x), jsonNumber(p.sigma)}));
    ordered out = {{"name", name_}, {"units", worldUnits_ ? "world" : "voxel"}, {"color", color}, {"extinction", sigma}};
    return out.dump(-1, ' ', false, ordered::error_handler_t::replace);
}

}  // namespace vdbsplat
