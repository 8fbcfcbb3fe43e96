// render/project_vector.h — the projection's common case, many voxels at once.
// Owns: projectSplatsVector, which projects up to kSplatLanes voxel centres as sphere-kernel
// splats in double precision with Google Highway (runtime dispatch: SSE4, AVX2, AVX-512 … one
// binary): the exact ellipse of the kernel sphere (projectSphere, DESIGN §2), the conic widened
// by the low-pass (makeScreenKernel), its pixel range (pixelRange), the affine-index error that
// picks --footprint auto's exact index, and that index's map (makeExactIndexMap). The same
// operations in the same order, without fused multiply-adds, so the same values bit for bit as
// the scalar functions (the oracle; tests/render/test_project_vector.cpp). Lanes the common case
// does not cover (behind or at the eye, straddling the eye plane, a point in hybrid, non-finite)
// are marked for the scalar path, which decides them as before.
#pragma once
#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>

#include "footprint/pixel_box.h"
#include "footprint/prefilter.h"
#include "footprint/screen_kernel.h"

namespace vdbsplat {

/// Voxels per call: a chunk of projectBatch's range (its arrays live on the stack).
inline constexpr size_t kSplatLanes = 64;

/// What every lane shares: the camera, the kernel and the rules (from ProjectionContext).
struct SplatLaneContext {
    double focal = 1.0;               ///< f (pixels)
    double principalX = 0.0, principalY = 0.0;
    double radius = 0.0;              ///< the kernel sphere's radius r = R·h (world units)
    double widenPerVariance = 0.0;    ///< (R/s_g)²: a low-pass V widens the support semi-axes² by it·V (px²)
    PrefilterRamp lowPass;            ///< V by the projected spacing h·f/z (ProjectionContext::lowPass)
    double spacingTimesFocal = 0.0;   ///< h·f: the projected spacing is h·f/z
    double threshold = 0.0;           ///< hybrid: a splat where h·f/z ≥ threshold; ignored when !pointsBelow
    bool pointsBelow = true;          ///< hybrid (points below the threshold); false: every voxel a splat
    bool autoExactIndex = true;       ///< --footprint auto: exact index where the affine error > kAutoExactIndexError
    double exactIndexError = 5e-4;    ///< that bound (render/project.h, kAutoExactIndexError)
    int width = 0, height = 0;        ///< image size (pixels)
};

/// One call's lanes, structure of arrays. In: x, y, z (view space). Out, per lane: `status`
/// kScalar (the scalar path decides), or kSplat or kExactIndex, plus kOffImage where its range has
/// no pixel (makeSplat then culls it, its fields computed all the same), and the splat's fields.
struct SplatLanes {
    static constexpr uint8_t kScalar = 0, kSplat = 1, kExactIndex = 2, kOffImage = 4;
    alignas(64) double x[kSplatLanes], y[kSplatLanes], z[kSplatLanes];
    // Out, in double (the scalar path's values; the caller rounds to the float fields).
    alignas(64) double amplitude[kSplatLanes];  ///< √(det V / det V'): scale = σ·amplitude
    alignas(64) double centreX[kSplatLanes], centreY[kSplatLanes];
    alignas(64) double conicXX[kSplatLanes], conicXY[kSplatLanes], conicYY[kSplatLanes];
    alignas(64) double sinAlpha[kSplatLanes];
    alignas(64) double x0[kSplatLanes], y0[kSplatLanes], x1[kSplatLanes], y1[kSplatLanes];  ///< integers
    /// kExactIndex: the map's 6 values (w0, wx, wy, wxx, wxy, wyy; ExactIndexMap), lane by lane.
    alignas(64) double map[6][kSplatLanes];
    uint8_t status[kSplatLanes];

    PixelRange range(size_t i) const { return {int(x0[i]), int(y0[i]), int(x1[i]), int(y1[i])}; }
    /// Lane @p i's map written into @p m field by field (the projection writes it straight into
    /// the window: a map returned through the stack and copied stalled on store forwarding, a
    /// quarter of the projection lambda's samples on the framed checker box).
    void exactMapInto(size_t i, ExactIndexMap& m) const;
    ExactIndexMap exactMap(size_t i) const {
        ExactIndexMap m;
        exactMapInto(i, m);
        return m;
    }
};

/// @brief Projects lanes [0, @p n) of @p lanes (n ≤ kSplatLanes; x, y, z set), writing their
/// status and, where the common case holds, the splat (see the file comment).
void projectSplatsVector(SplatLanes& lanes, size_t n, const SplatLaneContext& ctx);

/// What every point lane shares (hybrid or point mode, sphere kernels; from ProjectionContext).
struct PointLaneContext {
    double focal = 1.0;                  ///< f (pixels)
    double principalX = 0.0, principalY = 0.0;
    double spacingTimesFocal = 0.0;      ///< h·f: the projected spacing is h·f/z
    double threshold = 0.0;              ///< a point where h·f/z < threshold (point mode: +∞)
    double voxelSize = 1.0;              ///< h (world units)
    PrefilterRamp lowPass;               ///< V folded into each point by its spacing h·f/z (px²)
    double kernelSigma = 1.0;            ///< s_g (voxels)
    int width = 0, height = 0;           ///< image size (pixels)
};

/// The minified voxels of one call (DESIGN §4), structure of arrays: makePoint's point and
/// setUpPointFilter's filter for every lane the splat lanes left to the scalar path that is a
/// point (z > 0, h·f/z < threshold, finite; point mode's threshold is +∞). In: sigma (per voxel length) and spread
/// (an aggregate's, px²) per lane, the positions from SplatLanes. Out, per lane: `status` kPoint
/// and the record's fields, or kScalar: the scalar path decides (not a point, or a case it
/// keeps: a point makePoint culls, the one-pixel fallback of an empty filter sum).
struct PointLanes {
    static constexpr uint8_t kScalar = 0, kPoint = 1;
    alignas(64) float sigma[kSplatLanes], spread[kSplatLanes];
    alignas(64) float centreX[kSplatLanes], centreY[kSplatLanes];  ///< the float centre the record keeps
    alignas(64) float variance[kSplatLanes];                       ///< V_point (float, as Primitive::variance)
    alignas(64) float total[kSplatLanes];                          ///< Σ_pixels τ
    alignas(64) float invVariance[kSplatLanes], radius2[kSplatLanes], norm[kSplatLanes];  ///< PointSetup's
    alignas(64) int32_t x0[kSplatLanes], y0[kSplatLanes], nx[kSplatLanes], ny[kSplatLanes];  ///< the footprint (not clamped)
    uint8_t status[kSplatLanes];

    /// Lane @p i's footprint clamped to the image (setUpPointFilter's range).
    PixelRange range(size_t i, int width, int height) const {
        return {std::max(x0[i], 0), std::max(y0[i], 0), std::min(x0[i] + nx[i] - 1, width - 1),
                std::min(y0[i] + ny[i] - 1, height - 1)};
    }
};

/// @brief The points among lanes [0, @p n) of @p in (x, y, z set; a lane projectSplatsVector took
/// is no point), into @p out (sigma and spread set): makePoint and setUpPointFilter's
/// double and float operations in the same order, so the same record bit for bit (the scalar
/// path is the oracle; tests/render/test_project_vector.cpp), 16 points' filter sums at once.
void projectPointsVector(const SplatLanes& in, PointLanes& out, size_t n, const PointLaneContext& ctx);

/// @brief The depth slab of each of @p n distances: clamp(⌊double(distance) / slabLength⌋, @p first,
/// @p last), vectors at a time (the quotient correctly rounded, as the scalar division is, then
/// floored: the same integer as floorToInt64 of that quotient). projectBatch's one division per
/// voxel, out of the loop that builds the primitives, where its latency stalled each voxel.
/// Distances must be finite and under 2⁶² slab lengths; @p first ≤ @p last.
void slabsOf(const float* distance, size_t n, double slabLength, int64_t first, int64_t last, int64_t* slab);

}  // namespace vdbsplat
