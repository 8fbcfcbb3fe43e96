// render/project_modes.h — the projection of the study modes (DESIGN §6, docs/modes.md).
// Owns: what `--mode ewa`, `swan` and `none` build instead of hybrid's primitives, called
// from render/project.cpp's dispatch so that the point/splat decision, the near-eye fallback,
// the slab order and the compositor stay shared:
//   ewa  — every voxel in front of the eye a Gaussian splat from the affine approximation
//          (footprint/ewa.h), drawn as a Splat kind on the α = 0 row (d = i: no reindex);
//   swan — minified voxels' ellipses stretched to the pixel filter (footprint/swan.h);
//   none — splats without V_h (ProjectionContext::prefilterVariance = 0) and points snapped to
//          the pixel nearest their projection, all of their optical depth in that one pixel.
#pragma once
#include <glm/glm.hpp>

#include "composite/primitive.h"
#include "footprint/ellipse.h"
#include "footprint/screen_kernel.h"

namespace vdbsplat {

struct ProjectionContext;

/// A point's filter variance under --mode none: 3·√V = ½ px, so that rasterizePoint (pixel
/// centres strictly within 3√V) covers exactly the one pixel whose centre the point sits on.
inline constexpr double kNearestPixelVariance = 1.0 / 36.0;

/// @brief Makes @p p (a voxel at view point @p c whose kernel projects to the Ellipse @p sphere)
/// the EWA splat of Zwicker et al. 2001: a Splat at the projection of c, conic and amplitude from
/// makeEwaKernel, sin²α = 0 (the footprint table indexed by d = i). Culled when it is degenerate.
void fillEwaSplat(Primitive& p, const glm::dvec3& c, float sigma, const ProjectionContext& ctx);

/// @brief The screen kernel a splat of the Ellipse @p sphere gets in ctx.mode: Swan's stretch
/// for a minified voxel (projected spacing @p spacingPx < ctx.threshold) under --mode swan, the
/// EWA-widened exact ellipse (makeScreenKernel with @p lowPass, ctx.lowPass() at @p spacingPx) otherwise.
ScreenKernel splatKernelFor(const SphereProjection& sphere, double spacingPx, double lowPass, const ProjectionContext& ctx);

/// @brief True when the splat of @p spacingPx must take the table path whatever --footprint says
/// (a Swan-stretched kernel: the compositor's exact path would rebuild hybrid's kernel).
bool keepsTablePath(double spacingPx, const ProjectionContext& ctx);

/// @brief --mode none: moves the Point @p p to the centre of the pixel its projection falls in,
/// with variance kNearestPixelVariance and range that one pixel (its total is unchanged).
void snapToNearestPixel(Primitive& p, int width, int height);

}  // namespace vdbsplat
