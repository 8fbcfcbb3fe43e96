// composite/splat_raster.h — one splat's per-pixel loop over one tile, vectorised across pixels.
// Owns: SplatRaster (everything the loop needs, in float, prepared once per splat and tile),
// TileBuffers (a tile's transmittance and premultiplied colour, structure of arrays), and
// drawSplatVector, the Google Highway loop with runtime dispatch (SSE4, AVX2, AVX-512, NEON…
// whichever the CPU has; one binary runs everywhere).
//
// Per pixel it computes what the compositor's scalar table path does (TileCompositor::drawSplat
// with the tables, kept as the oracle the tests compare against), except that the footprint is
// the polynomial of footprint_poly.h instead of two dependent table lookups:
//     i² = Qxx dx² + 2 Qxy dx dy + Qyy dy²        (the widened conic, screen_kernel.h)
//     t  = i² (table path) or the exact d² (ExactIndexMap, --footprint auto off the axis)
//     τ  = scale · √(1 − t) · G_α(t)             (scale = σ·h·amplitude; DESIGN §3, §4)
//     α  = 1 − exp(−τ);  C += T·α·c;  T *= 1 − α  (DESIGN §4, front to back; the deposit that
//                                               takes T below ε takes all of it: the remainder)
// or, with `slabs` (--compositing slabs), τ·fraction_j and τ·fraction_j·c added to slab j's sums.
// Pixels with i² ≥ 1, outside the splat's clipped range or already opaque (T < ε) keep their values.
#pragma once
#include <cstdint>
#include <limits>
#include <glm/glm.hpp>

#include "composite/slab_profile.h"
#include "composite/tile.h"
#include "footprint/footprint_poly.h"
#include "footprint/screen_kernel.h"

namespace vdbsplat {

/// @brief One tile's pixels: row-major, stride kTileSize (composite/tile.h), 64-byte aligned arrays.
/// G and B null: one channel (ColorChannels::Grey, every colour grey): the loops composite T and R
/// alone, in the operations they give R with all four (and the slab order is not drawn this way).
struct TileBuffers {
    float* T;          ///< transmittance
    float* R;          ///< premultiplied radiance, per channel
    float* G;          ///< null with B: one channel
    float* B;
    int x0 = 0, y0 = 0;  ///< image coordinates of the tile's first pixel
};

/// @brief Which truncation of α = 1 − e^{−τ} a splat's deposits take, chosen from an upper bound
/// on every τ the splat deposits (SplatRaster::tauBound): the series to τ⁴ where τ ≤ 0.03 and to
/// τ⁶ where τ ≤ 0.2 (relative truncation error below τ⁴/120 ≤ 6.8e−9 and τ⁶/5040 ≤ 1.3e−8), else
/// the general form (the series to τ⁸ for a vector of τ < ½, else expm1; every one within
/// 1.4e−8·α). A CT's splats are mostly below 0.03 and a checker box's below 0.2, and the shorter
/// series save 4 and 2 FMAs and the per-vector test of the general form.
enum class OpacitySeries : uint8_t { Degree4, Degree6, Any };
inline OpacitySeries opacitySeriesFor(float tauBound) {
    if (tauBound <= 0.03f) return OpacitySeries::Degree4;  // false for NaN
    if (tauBound <= 0.2f) return OpacitySeries::Degree6;
    return OpacitySeries::Any;
}

struct SplatRaster {
    float cx = 0.f, cy = 0.f;             ///< widened ellipse centre (pixels)
    float qxx = 0.f, qxy = 0.f, qyy = 0.f;  ///< conic Q
    float scale = 0.f;                    ///< σ·h·amplitude
    FootprintPolynomials::Coefficients coef{};  ///< G_α (or the axis row for the exact index)
    bool exactIndex = false;              ///< t from `map` (exact d²) instead of i²
    ExactIndexMap map;                    ///< δ measured from (cx, cy)
    glm::vec3 color{0.f};
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  ///< inclusive image pixels, inside the tile
    float epsilon = 0.f;                  ///< pixels with T < epsilon are finished
    /// Lanes with T ≥ safeT cannot finish under this splat (remainderBound); the vector loop checks
    /// the others for a finishing deposit. +∞: it checks every lane (always right).
    float safeT = std::numeric_limits<float>::infinity();
    /// The truncation of 1 − e^{−τ} (OpacitySeries): must be opacitySeriesFor of a bound on every τ
    /// the splat deposits (scale · FootprintPolynomials::peak()); Any is right for every splat.
    OpacitySeries series = OpacitySeries::Any;
    /// --compositing slabs: deposit τ into these slab sums (composite/slab_profile.h) instead of
    /// compositing "over"; null: over.
    const SlabTargets* slabs = nullptr;
};

/// @brief Composites @p s "over" the pixels of @p tile (front to back).
void drawSplatVector(const SplatRaster& s, const TileBuffers& tile);

/// @brief Pixels of a tile, inclusive and tile-local (column x0 … x1 of rows y0 … y1); by default all.
struct TileRect {
    int x0 = 0, y0 = 0, x1 = kTileSize - 1, y1 = kTileSize - 1;
};

/// @brief A transmittance from which no deposit of optical depth ≤ @p tauBound brings a pixel
/// below @p epsilon (SplatRaster::safeT): ε·e^τ rounded up to ε·2^{⌊τ·log₂e⌋ + 2}, at least twice
/// it, which covers the float α's rounding; +∞ for τ ≥ 42. A deposit that does bring a pixel
/// below ε takes its whole remainder ("over", docs/compositing.md). Inline and without exp(): the
/// compositor asks once per splat and tile (std::exp there cost 5 % of a framed render).
inline float remainderBound(float epsilon, float tauBound) {
    const float n = tauBound * 1.44269504f;  // τ·log₂e
    if (!(n < 60.f)) return std::numeric_limits<float>::infinity();
    return epsilon * float(uint64_t(1) << (int(n) + 2));
}

/// @brief A slab's sums in the tile's pixels @p rect (both orders: the points' slabs of the kernel
/// order, every slab of --compositing slabs): the optical depth @p tau and σ-weighted emission
/// @p er, @p eg, @p eb (kTilePixels each) composited onto @p tile's live pixels (T ≥ @p epsilon),
/// α = 1 − e^{−τ}, C += T·α·e/τ, T *= 1 − α (or, where that leaves T < ε, the remainder: C += T·e/τ,
/// T = 0); then the slab emptied there. The rectangle's columns
/// are read in whole vectors: every pixel outside it must hold τ = 0 (it is left unchanged then).
/// A @p tile without G and B (one channel) reads and empties @p tau and @p er alone.
/// Vectorised (Highway).
void compositeSlabVector(float* tau, float* er, float* eg, float* eb, const TileBuffers& tile, float epsilon,
                         TileRect rect = {});

/// @brief The same loop one pixel at a time, in the same float operations (tests: the vector
/// loop must agree with it to float rounding).
void drawSplatScalarPoly(const SplatRaster& s, const TileBuffers& tile);

}  // namespace vdbsplat
