// render/render.h — the one entry point every caller renders through.
// Owns: turning (volume, settings) into an image: baking the transfer function
// for the grid's value range, building the camera, and dispatching to the mode
// (reference, hybrid, splat, point). The command line, the benchmark and the
// end-to-end tests all call render(), so they measure the same thing.
#pragma once
#include "camera/camera.h"
#include "image/image.h"
#include "render/settings.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

/// @brief The value range a grid's values are normalised from before classification:
/// [0, 1] when every finite active value lies in it, else the grid's [min, max].
void normalizationRange(const Volume& volume, float& lo, float& hi);

/// @brief Refuses a grid with more active voxels than settings.maxActiveVoxels (before any work).
/// @throw Error naming the file, the count, the limit and --max-voxels.
void checkVoxelBudget(const Volume& volume, const RenderSettings& settings);

/// @brief The camera @p settings describe for @p volume (framing its world bounds by default).
/// @throw Error "--eye: …" when the eye is more than kMaxEyeDistanceInDiagonals bounding-box
/// diagonals from the grid.
Camera cameraFor(const Volume& volume, const RenderSettings& settings);

/// @brief True when every active voxel of @p volume projects under @p thresholdPx pixels on
/// @p camera (all would be points): the projected spacing (longest voxel axis)·f/z at the
/// nearest corner of the active voxels' box. False when a corner lies at or behind the eye.
bool everyVoxelMinified(const Volume& volume, const Camera& camera, double thresholdPx);

/// @brief @p settings with what is automatic for a view made concrete for @p volume on @p camera:
/// subpixels (RenderSettings::effectiveSubpixels). render() renders with it; callers use it to
/// echo the settings an image was made with.
RenderSettings resolvedFor(const Volume& volume, const Camera& camera, RenderSettings settings);

/// @brief Renders @p volume with @p settings (already validated) and transfer function @p tf.
/// Uses the calling thread's TBB arena (the caller limits threads with tbb::global_control).
/// @throw Error for settings the mode cannot honour.
/// @param control optional progress report and stop request (Ctrl-C); see RenderControl.
/// @throw RenderStopped when control.stop returned true.
/// stats.seconds and stats.pageFaults cover the whole call, the full image's placement included.
Image render(const Volume& volume, const TransferFunction& tf, const RenderSettings& settings, RenderStats& stats,
             const RenderControl& control = {});

/// @brief render() without placing the image: the forward modes' image as its data window (the
/// pixels the volume can reach; render/hybrid.h), the reference's whole. stats.seconds and
/// stats.pageFaults cover this call. What `render` and `bench` use: writing a PNG reads the window
/// alone (writeImage), and a far view's full image is written a fresh page a row (session 46).
WindowedImage renderWindowed(const Volume& volume, const TransferFunction& tf, const RenderSettings& settings,
                             RenderStats& stats, const RenderControl& control = {});

}  // namespace vdbsplat
