// volume/emission.h — emission grids: a second scalar grid (temperature, flame) whose values
// add emitted radiance to the density's, on the same kernels (DESIGN §1, docs/emission.md).
// Owns: EmissionSettings (--emission, --emission-map, --emission-scale, --kelvin: validated,
// echoed into JSON), the blackbody colour map (Planck's law through the CIE 1931 observer to
// linear sRGB), the baked emission table (raw value → ε, emitted radiance per voxel length),
// attachEmission (the checks a second grid must pass, and the union of the two topologies),
// and applyEmission (how one voxel's classification takes its emission).
//
// The model (docs/emission.md): the emitted radiance density is
//     Σ_k (σ_k c_k + e_k) g((x − x_k)/h),     ε_k = e_k·h  (per voxel length, like σ_k·h),
// the extinction stays Σ_k σ_k g. The kernels are those of the union of the two grids' active
// voxels; where the density grid is inactive its value is its background (normally 0: no
// extinction). Every renderer composites one (τ, colour) pair per kernel, so a voxel carries
//     σ' = max(σ, kEmissionOnlySigma),   c' = (σ c + ε) / σ'
// — exact for σ > 0 (emission and extinction share the kernel: the ratio is constant along
// the ray inside it), and for σ = 0 a pure emitter with a negligible extinction (below).
#pragma once
#include <glm/glm.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// Extinction (per voxel length) given to a voxel that emits but has no extinction of its own,
/// so that it composites like every other kernel: it deposits ε·F·(1 − τ/2 + …) with
/// τ ≤ 1.1e−6 (F ≤ 1.1 voxels), a relative loss below 6e−7, and dims what lies behind it by the
/// same. The forward modes and the reference use the same σ', so they render the same field;
/// the float paths keep full precision there (α = 1 − e^{−τ} is the Taylor series or expm1).
inline constexpr float kEmissionOnlySigma = 1e-6f;

/// Blackbody map: the default Kelvin range normalised values are mapped to. 1500 K is a dull
/// red glow, 6500 K about the sRGB white point (docs/emission.md).
inline constexpr double kDefaultKelvinLo = 1500.0, kDefaultKelvinHi = 6500.0;

struct EmissionSettings {
    std::string grid;                 ///< the emission grid's name; empty: no emission
    std::string map = "blackbody";    ///< "blackbody", or a transfer function (preset or JSON file)
    double scale = 1.0;               ///< --emission-scale: ε at the map's brightest value, per voxel length
    double kelvinLo = kDefaultKelvinLo, kelvinHi = kDefaultKelvinHi;  ///< blackbody: x = 0 and x = 1

    bool active() const { return !grid.empty(); }
    bool blackbody() const { return map == "blackbody"; }
    /// @throw Error naming the flag of the first invalid value.
    void validate() const;
    nlohmann::json toJson() const;
};

/// @brief The emission grid attached to a density Volume (attachEmission).
struct EmissionGrid {
    std::shared_ptr<const openvdb::FloatTree> tree;  ///< values as float, non-finite values zeroed
    std::string name;
    float valueMin = 0.f, valueMax = 1.f;  ///< range of its finite active values
    uint64_t activeVoxels = 0;
    uint64_t outsideDensity = 0;      ///< its active voxels where the density grid was inactive
};

/// @brief Linear sRGB of a blackbody at @p kelvin, scaled to luminance Y = 1: Planck's spectral
/// radiance integrated against the CIE 1931 2° colour-matching functions (the multi-lobe fit of
/// Wyman, Sloan and Shirley 2013, their eq. 2), 360–830 nm, then XYZ → linear sRGB (IEC
/// 61966-2-1). Negative channels (out of the sRGB gamut, below ~2000 K) are clipped to 0.
glm::vec3 blackbodyRgb(double kelvin);

/// @brief The blackbody map at normalised value @p x ∈ [0, 1]: T = lo + x (hi − lo), colour
/// blackbodyRgb(T), brightness (T⁴ − lo⁴)/(hi⁴ − lo⁴) (Stefan–Boltzmann, 0 at the range's
/// start, 1 at its end), times @p scale.
glm::vec3 blackbodyEmission(double x, double lo, double hi, double scale);

/// @brief The emission table for a grid with values normalised from [@p valueMin, @p valueMax]:
/// entry colours hold ε (emitted radiance per voxel length), extinctions are 0. Blackbody:
/// blackbodyEmission; a transfer function @p tf: ε = scale · σ(x)·c(x), its emission term
/// without its extinction (σ per voxel length, world units converted with @p voxelSize).
ClassificationTable bakeEmission(const EmissionSettings& s, const TransferFunction* tf, float valueMin, float valueMax,
                                 double voxelSize);

/// @brief The per-render emission lookup: ε of an active emission voxel, 0 elsewhere.
/// Immutable; each thread passes its own accessor.
class EmissionSource {
public:
    using Accessor = openvdb::tree::ValueAccessor<const openvdb::FloatTree, false>;
    EmissionSource(const EmissionGrid& grid, ClassificationTable table) : grid_(grid), table_(std::move(table)) {}
    Accessor accessor() const { return Accessor(*grid_.tree); }
    /// ε at voxel @p ijk (RGB, per voxel length); 0 where the emission grid is inactive.
    glm::vec3 at(Accessor& acc, const openvdb::Coord& ijk) const {
        float v;
        return acc.probeValue(ijk, v) ? table_(v).color : glm::vec3(0.f);
    }

private:
    const EmissionGrid& grid_;
    ClassificationTable table_;
};

/// @brief The emission source @p settings describe for @p volume's attached grid.
/// @throw Error "--emission-map: …" for an unknown map; Error when no grid is attached.
std::unique_ptr<EmissionSource> makeEmissionSource(const Volume& volume, const EmissionSettings& settings);

/// @brief A voxel's classification with its emission @p epsilon (see the model above).
inline Classified applyEmission(const Classified& c, const glm::vec3& epsilon) {
    if (!(epsilon.x > 0.f || epsilon.y > 0.f || epsilon.z > 0.f)) return c;
    const float sigma = std::max(c.sigma, kEmissionOnlySigma);
    return {(c.sigma * c.color + epsilon) / sigma, sigma};
}

/// @brief Attaches @p emission to @p density: both grids must have the same transform (voxel
/// size, orientation and offset). Voxels active only in the emission grid become active in the
/// density grid with its background value (its value there), so the two grids share kernels.
/// @throw Error naming the file and both grids when the transforms differ.
void attachEmission(Volume& density, Volume emission);

/// @brief Loads the density grid @p gridName and, when @p emissionGrid is not empty, the
/// emission grid of that name from the same file, attached (loadVolume's errors, then
/// attachEmission's).
Volume loadVolumeWithEmission(const std::string& path, const std::string& gridName, const std::string& emissionGrid);

}  // namespace vdbsplat
