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
#include <string>
#include <vector>

namespace vdbsplat {

/// @brief The classified value of one voxel.
struct Classified {
    glm::vec3 color{0.f};  ///< emitted colour c_k (linear RGB)
    float sigma = 0.f;     ///< extinction σ_k · h: optical depth per voxel length
};

/// @brief A baked transfer function: a dense table over the normalised value.
class ClassificationTable {
public:
    static constexpr int kSize = 4096;
    ClassificationTable() = default;
    ClassificationTable(std::vector<Classified> entries, float valueMin, float valueMax);
    /// @brief Classifies a raw voxel value (normalised with the grid's range); non-finite → σ = 0.
    Classified operator()(float value) const;
    /// @brief True if no value maps to a positive extinction (nothing to render).
    bool empty() const;
private:
    std::vector<Classified> entries_;
    float valueMin_ = 0.f, scale_ = 1.f;
};

class TransferFunction {
public:
    struct ColorPoint { float x; glm::vec3 rgb; };
    struct ExtinctionPoint { float x; float sigma; };

    /// @brief A built-in preset: "grey", "ct-bone", "fire" (see presetNames()).
    /// @throw Error "unknown transfer function preset '<name>' (choose …)".
    static TransferFunction preset(const std::string& name);
    static std::vector<std::string> presetNames();
    /// @brief A preset name or a JSON file (vdbsplat format, or a ParaView colour map).
    /// @throw Error naming the file and the reason when invalid.
    static TransferFunction fromSpec(const std::string& presetOrFile);
    /// @brief Parses JSON text; @p origin names the source in error messages.
    static TransferFunction fromJson(const std::string& text, const std::string& origin);

    /// @brief Colour and extinction at normalised value @p x ∈ [0, 1] (piecewise linear, clamped).
    Classified evaluate(float x) const;
    /// @brief Bakes a table for a grid with values in [valueMin, valueMax] and voxel size @p h.
    ClassificationTable bake(float valueMin, float valueMax, double voxelSize) const;

    const std::string& name() const { return name_; }
    /// @brief The whole function as compact JSON (for EXR metadata and stats).
    std::string toJson() const;

private:
    std::string name_;
    std::vector<ColorPoint> colors_;
    std::vector<ExtinctionPoint> extinction_;
    bool worldUnits_ = false;
};

}  // namespace vdbsplat
