// volume/emission.cpp — emission grids (see emission.h, docs/emission.md).
#include "volume/emission.h"

#include <cmath>
#include <sstream>

#include "util/error.h"

namespace vdbsplat {

namespace {

/// One lobe of the Wyman–Sloan–Shirley 2013 fit: a Gaussian with different widths left and
/// right of its mean (their eq. 2), λ in nm.
double lobe(double lambda, double mu, double left, double right) {
    const double t = (lambda - mu) / (lambda < mu ? left : right);
    return std::exp(-0.5 * t * t);
}

/// CIE 1931 2° colour-matching functions x̄, ȳ, z̄ (Wyman, Sloan, Shirley 2013, multi-lobe fit, eq. 2).
glm::dvec3 cie1931(double lambda) {
    const double x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7) -
                     0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    const double y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    const double z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    return {x, y, z};
}

/// Planck's law up to a constant factor: B(λ, T) ∝ λ⁻⁵ / (exp(c₂/(λT)) − 1), c₂ = hc/k.
double planck(double lambdaNm, double kelvin) {
    constexpr double c2 = 1.4387769e-2;  // m·K (CODATA 2018)
    const double lambda = lambdaNm * 1e-9;
    return 1.0 / (std::pow(lambdaNm * 1e-3, 5.0) * std::expm1(c2 / (lambda * kelvin)));
}

/// The value range a grid is normalised from (the rule render/render.h applies to density):
/// [0, 1] when every finite active value lies in it, else [min, max].
void normalisedRange(float valueMin, float valueMax, float& lo, float& hi) {
    if (valueMin >= 0.f && valueMax <= 1.f) {
        lo = 0.f, hi = 1.f;
        return;
    }
    lo = valueMin;
    hi = valueMax > valueMin ? valueMax : valueMin + 1.f;
}

std::string describeVoxelSize(const Volume& volume) {
    std::ostringstream s;
    s.precision(6);
    const openvdb::Vec3d v = volume.map->voxelSize();
    s << v.x() << " x " << v.y() << " x " << v.z();
    return s.str();
}

}  // namespace

void EmissionSettings::validate() const {
    if (!(std::isfinite(scale) && scale >= 0.0 && scale <= 1e6)) throw Error("--emission-scale: must be in [0, 1e6]");
    if (!(std::isfinite(kelvinLo) && std::isfinite(kelvinHi) && kelvinLo >= 100.0 && kelvinHi <= 1e5 &&
          kelvinLo < kelvinHi))
        throw Error("--kelvin: expected LO,HI with 100 <= LO < HI <= 100000");
    if (map.empty()) throw Error("--emission-map: expected 'blackbody', a preset or a JSON file, got ''");
}

nlohmann::json EmissionSettings::toJson() const {
    nlohmann::json j;
    j["grid"] = grid;
    j["map"] = map;
    j["scale"] = scale;
    if (blackbody()) j["kelvin"] = {kelvinLo, kelvinHi};
    return j;
}

glm::vec3 blackbodyRgb(double kelvin) {
    glm::dvec3 xyz(0.0);
    for (double lambda = 360.0; lambda <= 830.0; lambda += 1.0) xyz += planck(lambda, kelvin) * cie1931(lambda);
    if (!(xyz.y > 0.0)) return glm::vec3(0.f);
    xyz /= xyz.y;  // luminance 1
    // XYZ → linear sRGB (IEC 61966-2-1, D65).
    const glm::dvec3 rgb(3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
                         -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
                         0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z);
    return glm::vec3(glm::max(rgb, glm::dvec3(0.0)));
}

glm::vec3 blackbodyEmission(double x, double lo, double hi, double scale) {
    x = std::clamp(x, 0.0, 1.0);
    const double T = lo + x * (hi - lo);
    const double lo4 = std::pow(lo, 4.0), brightness = (std::pow(T, 4.0) - lo4) / (std::pow(hi, 4.0) - lo4);
    return blackbodyRgb(T) * float(scale * brightness);
}

ClassificationTable bakeEmission(const EmissionSettings& s, const TransferFunction* tf, float valueMin, float valueMax,
                                 double voxelSize) {
    constexpr int n = ClassificationTable::kSize;
    std::vector<Classified> entries(n);
    // The blackbody colour changes slowly with T: 256 spectra, linearly interpolated (within 9.2e−5 of
    // the direct integral over 1500–6500 K, relative to the largest channel; docs/emission.md).
    constexpr int kSpectra = 256;
    std::vector<glm::vec3> coarse;
    if (!tf) {
        coarse.resize(kSpectra + 1);
        for (int k = 0; k <= kSpectra; ++k) coarse[size_t(k)] = blackbodyRgb(s.kelvinLo + (s.kelvinHi - s.kelvinLo) * k / kSpectra);
    }
    const double lo4 = std::pow(s.kelvinLo, 4.0), hi4 = std::pow(s.kelvinHi, 4.0);
    for (int i = 0; i < n; ++i) {
        const double x = double(i) / (n - 1);
        if (tf) {
            const Classified c = tf->evaluate(float(x));
            const double perVoxel = tf->worldUnits() ? voxelSize : 1.0;
            entries[size_t(i)].color = c.color * float(s.scale * c.sigma * perVoxel);
        } else {
            const double at = x * kSpectra;
            const int k = std::min(int(at), kSpectra - 1);
            const glm::vec3 rgb = glm::mix(coarse[size_t(k)], coarse[size_t(k) + 1], float(at - k));
            const double T = s.kelvinLo + x * (s.kelvinHi - s.kelvinLo);
            entries[size_t(i)].color = rgb * float(s.scale * (std::pow(T, 4.0) - lo4) / (hi4 - lo4));
        }
    }
    float lo, hi;
    normalisedRange(valueMin, valueMax, lo, hi);
    return ClassificationTable(std::move(entries), lo, hi);
}

std::unique_ptr<EmissionSource> makeEmissionSource(const Volume& volume, const EmissionSettings& settings) {
    if (!volume.emission) throw Error("--emission: grid '" + settings.grid + "' was not loaded");
    const EmissionGrid& g = *volume.emission;
    std::unique_ptr<TransferFunction> tf;
    if (!settings.blackbody()) {
        try {
            tf = std::make_unique<TransferFunction>(TransferFunction::fromSpec(settings.map));
        } catch (const Error& e) {
            throw Error(std::string("--emission-map: ") + e.what());
        }
    }
    return std::make_unique<EmissionSource>(g, bakeEmission(settings, tf.get(), g.valueMin, g.valueMax, volume.voxelSize));
}

void attachEmission(Volume& density, Volume emission) {
    const std::string where = emission.file.empty() ? std::string("<memory>") : emission.file;
    if (!sameTransform(emission, density))
        throw Error(where + ": emission grid '" + emission.name + "' has another transform than density grid '" +
                    density.name + "' (voxel size " + describeVoxelSize(emission) + " against " + describeVoxelSize(density) +
                    "); both must share voxel size, orientation and offset");
    auto out = std::make_shared<EmissionGrid>();
    out->tree = emission.tree;
    out->name = emission.name;
    out->valueMin = emission.valueMin, out->valueMax = emission.valueMax;
    out->activeVoxels = emission.activeVoxels;
    // The emission-only voxels: active in the emission grid, not in the density grid.
    openvdb::BoolTree only(*emission.tree, false, openvdb::TopologyCopy());
    only.topologyDifference(*density.tree);
    out->outsideDensity = only.activeVoxelCount();
    if (out->outsideDensity > 0) {
        openvdb::FloatTree& tree = *density.tree;
        const float background = tree.background();
        tree.topologyUnion(*emission.tree);
        // Activated voxels keep whatever inactive value the density leaf held: set the background.
        for (auto it = only.cbeginValueOn(); it; ++it) {
            if (it.isVoxelValue()) tree.setValueOn(it.getCoord(), background);
            else tree.fill(it.getBoundingBox(), background, true);
        }
        density.activeVoxels = tree.activeVoxelCount();
        density.indexBox = activeVoxelBounds(tree);
    }
    density.emission = std::move(out);
}

Volume loadVolumeWithEmission(const std::string& path, const std::string& gridName, const std::string& emissionGrid) {
    Volume density = loadVolume(path, gridName);
    if (emissionGrid.empty()) return density;
    if (emissionGrid == density.name)
        throw Error(path + ": --emission grid '" + emissionGrid + "' is the density grid; name another grid");
    attachEmission(density, loadVolume(path, emissionGrid));
    return density;
}

}  // namespace vdbsplat
