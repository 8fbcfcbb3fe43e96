// composite/primitive.h — the projected primitives the compositor consumes.
// Owns: Primitive, the one record per voxel that leaves the projection stage
// (render/project.h) and enters the tile compositor (composite/compositor.h):
// a filtered point (DESIGN §4, circular pixel filter w), an EWA splat (exact
// ellipse widened by the low-pass, (i, α) reindex + footprint table), or a
// near-eye kernel drawn with the exact half-ray integral (ellipse.h fallback).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "footprint/pixel_box.h"
#include "footprint/screen_kernel.h"
#include "util/huge_pages.h"

namespace vdbsplat {

enum class PrimitiveKind : uint8_t {
    Culled = 0,    ///< off screen, behind the eye, or empty: draws nothing
    Point = 1,     ///< minified voxel: w(p − centre) with variance `variance`, total optical depth `total`
    Splat = 2,     ///< magnified voxel, table path: conic + SplatShader
    SplatExact = 3,///< magnified voxel, --footprint exact: recomputed per tile from viewPos
    SplatExactIndex = 5, ///< magnified voxel, --footprint auto, far off-axis: exact index d per pixel
                         ///< (kernel recomputed per tile from viewPos) into the footprint table
    NearEye = 4,   ///< kernel containing the eye or straddling the eye plane: exact half-ray integral
};

struct Primitive {
    // What the compositor's key pass and gather read comes first (two cache lines; the
    // exact-index map and the recompute fields after them are read only for their kinds).
    PrimitiveKind kind = PrimitiveKind::Culled;
    bool hasExactMap = false;   ///< SplatExactIndex: exactMap is set
    int64_t slab = 0;           ///< depth slab (points of one slab are summed before compositing)
    float depth = 0.f;          ///< radial distance of the voxel centre (world units): the order
    uint32_t members = 1;       ///< active voxels it stands for (a level-of-detail aggregate: more)
    PixelRange range;           ///< the image pixels it may touch (clamped)
    glm::vec3 color{0.f};       ///< emitted colour (already tinted for --show-primitives)
    glm::vec2 centre{0.f};      ///< point position / ellipse centre (pixels)
    // Point
    float variance = 0.f;       ///< V_point, px²
    float total = 0.f;          ///< Σ_pixels τ (DESIGN §4 energy rule)
    /// The filter set up once from centre and variance (pointfilter/point_filter.h, PointSetup);
    /// `range` is then its footprint clamped to the image (empty: nothing on screen).
    float pointInvVariance = 0.f, pointRadius2 = 0.f, pointNorm = 0.f;
    // Splat (table path)
    glm::vec3 conic{0.f};       ///< Q as (Qxx, Qxy, Qyy): i² = Qxx dx² + 2 Qxy dx dy + Qyy dy²
    float scale = 0.f;          ///< σ_k·h·amplitude (SplatShader::scale)
    float sin2Alpha = 0.f;      ///< sin²α: the vector loop's polynomial row, the table path's
                                ///< reindex row through halfConeAngle()
    // SplatExactIndex: the exact d² as an affine map of the pixel (δ from `centre`), set up once
    ExactIndexMap exactMap;
    // SplatExact / NearEye (recomputed from these per tile; they are rare or a diagnostic)
    glm::vec3 viewPos{0.f};
    float sigma = 0.f;          ///< extinction per voxel length
};

/// The projected window: reused window after window, in huge pages (util/huge_pages.h).
using PrimitiveBuffer = std::vector<Primitive, HugePageAllocator<Primitive>>;

/// @brief The half cone angle α = asin(sin α) of a splat from its stored sin²α (DESIGN §2):
/// the table path's reindex row; the projection itself needs no trigonometry.
inline double halfConeAngle(float sin2Alpha) { return std::asin(std::sqrt(std::clamp(double(sin2Alpha), 0.0, 1.0))); }

}  // namespace vdbsplat
