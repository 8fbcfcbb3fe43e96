// volume/transfer_function.h — classification: value → (extinction σ, colour c).
// Owns: piecewise-linear transfer functions over the normalised value in [0, 1],
// the built-in presets, the JSON format (docs/transfer-functions.md), ParaView
// colour maps (RGBPoints), and the baked lookup table the renderers use.
//
// Extinction units: a transfer function's extinction is per voxel ("units":
// "voxel", the default, so a preset looks alike at any voxel size) or per world
// unit ("units": "world"). bake() turns either into optical depth per voxel
// length (σ·h), the unit every renderer integrates in.
#pragma once
#include <glm/glm.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbsplat {

/// @brief The classified value of one voxel.
struct Classified {
    glm::vec3 color{0.f};  ///< emitted colour c_k (linear RGB)
    float sigma = 0.f;     ///< extinction σ_k · h: optical depth per voxel length
};

/// @brief A piecewise-linear function's pieces over the table index x ∈ [0, kSize − 1]: piece j
/// starts at knot[j] (knot[0] = 0, increasing) and runs to the next knot (the last to the end); on
/// it, channel c (r, g, b, σ) is value[c][j] + slope[c][j] · (x − knot[j]), σ kept ≥ 0. Sixteen
/// pieces at most, so that a vector of 16 floats (or two of 8) holds each column and a lane finds
/// its piece's numbers by a permute instead of a gather (volume/classify-inl.h).
struct LinearPieces {
    static constexpr int kMax = 16;
    /// The index range split into kMax equal buckets of kBucketWidth (bucket of x: int(x) >> 8),
    /// so that a lane finds its piece by a permute and a few compares (volume/classify-inl.h).
    static constexpr int kBucketShift = 8, kBucketWidth = 1 << kBucketShift;
    int count = 0;  ///< pieces in use, 1..kMax (0: none)
    alignas(64) float knot[kMax] = {};
    alignas(64) float value[4][kMax] = {};  ///< r, g, b, σ at each piece's knot
    alignas(64) float slope[4][kMax] = {};  ///< r, g, b, σ per unit of x along each piece
    alignas(64) float next[kMax] = {};       ///< knot[j + 1]; +∞ for the last piece
    alignas(64) int32_t firstOfBucket[kMax] = {};  ///< piece(b · kBucketWidth) of bucket b
    int knotsPerBucket = 0;  ///< most knots strictly inside one bucket (compares after the permute)

    /// The piece of index @p x ∈ [0, kMax · kBucketWidth): how many knots after the first lie at
    /// or below it, from its bucket's first piece on (index() must have run).
    int piece(float x) const {
        int j = firstOfBucket[int(x) >> kBucketShift];
        while (x >= next[j]) ++j;  // next[count − 1] = +∞
        return j;
    }
    /// The function at index @p x, in the float operations the vector form repeats.
    Classified operator()(float x) const {
        const int j = piece(x);
        const float d = x - knot[j];
        const auto at = [&](int c) { return value[c][j] + slope[c][j] * d; };
        const float sigma = at(3);
        return {glm::vec3(at(0), at(1), at(2)), sigma > 0.f ? sigma : 0.f};
    }
    /// count in 0..kMax; knots from 0, not decreasing, at most kSize − 1; finite values, slopes.
    bool valid() const;
    /// Fills next, firstOfBucket and knotsPerBucket from count and knot.
    void index();
    /// The first piece with σ > 0 somewhere (σ ≥ 0 at its knot, so its value or slope is); count
    /// when none.
    int firstOpaque() const {
        int j = 0;
        while (j < count && !(value[3][j] > 0.f || slope[3][j] > 0.f)) ++j;
        return j;
    }
};

/// @brief A baked transfer function: a dense table over the normalised value, and, where the
/// function has at most LinearPieces::kMax linear pieces, those pieces exactly.
///
/// Entry i holds the function at x_i = i / (kSize − 1); a raw value v maps to the
/// continuous index (v − valueMin) · (kSize − 1) / (valueMax − valueMin), so
/// valueMin lands exactly on entry 0 and valueMax exactly on entry kSize − 1,
/// and values outside the range clamp to the end entries. A degenerate range
/// (valueMax ≤ valueMin: a grid holding one value) maps every value to x = 1.
/// With pieces, classification evaluates them at x (the function itself, to float rounding);
/// without, it lerps the two nearest entries (within one entry of a knot, the table rounds the
/// knot's corner off).
class ClassificationTable {
public:
    static constexpr int kSize = 4096;
    ClassificationTable() = default;
    /// @param entries   kSize entries (x_i = i / (kSize − 1)); an empty vector classifies all to zero
    /// @param valueMin  raw value mapped to x = 0
    /// @param valueMax  raw value mapped to x = 1
    /// @param pieces    the same function's linear pieces in the index x, if it has few
    ///                  (TransferFunction::bake); count 0: classify through the entries
    ClassificationTable(std::vector<Classified> entries, float valueMin, float valueMax,
                        const LinearPieces& pieces = {});

    /// @brief Classifies a raw voxel value (normalised with the grid's range); non-finite → all zero.
    /// The pieces at x, else linear interpolation between the two nearest entries; hot path, inline.
    Classified operator()(float value) const {
        if (!std::isfinite(value) || entries_.empty()) return {};
        const float x = std::clamp(value * scale_ + offset_, 0.f, float(kSize - 1));
        if (pieces_.count) return pieces_(x);
        const int i = std::min(int(x), kSize - 2);
        const float t = x - float(i);
        const Classified& a = entries_[size_t(i)];
        const Classified& b = entries_[size_t(i) + 1];
        return {a.color + t * (b.color - a.color), a.sigma + t * (b.sigma - a.sigma)};
    }
    /// @brief Extinction only (σ·h per voxel length) — for passes that need no colour.
    float sigma(float value) const { return (*this)(value).sigma; }
    /// @brief True if no value maps to a positive extinction (nothing to render).
    bool empty() const;
    /// @brief True if every value classifies to a grey colour (r = g = b, bit for bit): every entry,
    /// and every piece's values and slopes channel for channel, so each channel takes the same
    /// float operations on the same numbers (composite/compositing.h, ColorChannels::Grey). Found
    /// once, when the table is made (every render asks).
    bool grey() const { return grey_; }
    /// @brief The continuous table index a raw value maps to (unclamped; for tests).
    float indexOf(float value) const { return value * scale_ + offset_; }
    /// @brief The kSize entries (nullptr when empty) and the index map value·scale + offset:
    /// for vectorised classification that must agree with operator() (volume/leaf_moments.h).
    const Classified* entries() const { return entries_.empty() ? nullptr : entries_.data(); }
    /// @brief The exact pieces (count 0 when the function has more than LinearPieces::kMax, or
    /// the table was built from entries alone).
    const LinearPieces& pieces() const { return pieces_; }
    float scale() const { return scale_; }
    float offset() const { return offset_; }
    /// @brief Every index x < transparentBelow() (x = value·scale + offset, clamped) classifies to
    /// σ = 0 exactly: both entries operator() lerps have σ = 0, or (with pieces) its piece's σ
    /// value and slope are 0. −1 when entry 0 (piece 0) has σ ≠ 0 (or is NaN); kSize − 1 when
    /// nothing is positive. Lets vectorised passes skip transparent voxels.
    float transparentBelow() const { return transparentBelow_; }

private:
    std::vector<Classified> entries_;
    LinearPieces pieces_;
    float scale_ = float(kSize - 1);  ///< index = value · scale_ + offset_
    float offset_ = 0.f;
    float transparentBelow_ = -1.f;  ///< see transparentBelow()
    bool grey_ = true;               ///< see grey(); an empty table draws nothing
};

/// @brief A piecewise-linear transfer function over the normalised value x ∈ [0, 1].
class TransferFunction {
public:
    struct ColorPoint { float x; glm::vec3 rgb; };       ///< linear RGB in [0, 1]
    struct ExtinctionPoint { float x; float sigma; };    ///< σ ≥ 0 in the function's units

    /// @brief Largest transfer-function file fromSpec() reads.
    static constexpr size_t kMaxFileBytes = size_t(16) << 20;

    /// @brief A built-in preset: "grey", "ct-bone", "fire" (see presetNames()).
    /// @throw Error "unknown transfer function preset '<name>' (choose …)".
    static TransferFunction preset(const std::string& name);
    /// @brief Names of the built-in presets, in a fixed order.
    static std::vector<std::string> presetNames();
    /// @brief A preset name or a JSON file (vdbsplat format, or a ParaView colour map).
    /// @throw Error naming the file and the reason when invalid, or
    ///        "unknown transfer function preset or file '<s>' (presets: …)".
    static TransferFunction fromSpec(const std::string& presetOrFile);
    /// @brief Parses JSON text; @p origin names the source in error messages.
    /// @throw Error "<origin>: <reason>" (one line) when invalid.
    static TransferFunction fromJson(const std::string& text, const std::string& origin);
    /// @brief Builds a function from points (validated as a file would be).
    /// @throw Error "<name>: <reason>" when the points are invalid.
    static TransferFunction fromPoints(std::string name, std::vector<ColorPoint> colors,
                                       std::vector<ExtinctionPoint> extinction, bool worldUnits = false);

    /// @brief Colour and extinction at normalised value @p x ∈ [0, 1] (piecewise linear, clamped;
    /// non-finite x → all zero). Extinction is in the function's own units (see worldUnits()).
    Classified evaluate(float x) const;
    /// @brief Bakes a table for a grid with values in [valueMin, valueMax] and voxel size @p h.
    /// @throw Error when the range is not finite or (world units) h is not finite and positive.
    ClassificationTable bake(float valueMin, float valueMax, double voxelSize) const;
    /// @brief The function's linear pieces in the table index (σ times @p perVoxel); count 0 when
    /// it has more than LinearPieces::kMax.
    LinearPieces pieces(float perVoxel) const;

    const std::string& name() const { return name_; }
    bool worldUnits() const { return worldUnits_; }
    const std::vector<ColorPoint>& colors() const { return colors_; }
    const std::vector<ExtinctionPoint>& extinction() const { return extinction_; }
    /// @brief The whole function as compact JSON (for EXR metadata and stats); fromJson reads it back.
    std::string toJson() const;

private:
    std::string name_;
    std::vector<ColorPoint> colors_;
    std::vector<ExtinctionPoint> extinction_;
    bool worldUnits_ = false;
};

}  // namespace vdbsplat
