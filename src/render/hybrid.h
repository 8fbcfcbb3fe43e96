// render/hybrid.h — the forward-resampling modes: hybrid, splat-only, point-only.
// Owns: the pipeline grid → voxel stream (volume/stream.h) → projected
// primitives (render/project.h) → tile compositor (composite/compositor.h) →
// image, window by window, front to back (Yuan et al. 2003 with the EWA filter).
#pragma once
#include "camera/camera.h"
#include "footprint/tables.h"
#include "image/image.h"
#include "render/settings.h"
#include "shading/shading_field.h"
#include "volume/emission.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat {

class PendingTables;  // render/pending_tables.h

/// @brief Renders @p volume in settings.mode (Hybrid, Splat or Point).
/// @p tables: for settings.kernel, waited for where the compositor first needs them.
/// @p emission: each voxel's emission (nullptr: none; docs/emission.md).
/// @return the image as its data window: the pixels the volume's primitives can reach (all of
/// the image where no crop applies); transparent elsewhere.
WindowedImage renderForward(const Volume& volume, const ClassificationTable& table, const Camera& camera,
                            PendingTables& tables, const RenderSettings& settings, RenderStats& stats,
                            const VoxelShader* shader = nullptr, const RenderControl& control = {},
                            const EmissionSource* emission = nullptr);

}  // namespace vdbsplat
