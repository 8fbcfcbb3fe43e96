// cli/render_flags.h — the render flags shared by `vdbsplat render`, `animate`, `study` and `bench`.
// Owns: the one declaration of each render flag (--mode, --size, --tf, --grid, --fov, --distance,
// --threads, --spp, --threshold, --footprint, --filter-order, --subpixels, --lod, --simd,
// --show-primitives, --tables, --max-voxels, --kernel, --up, --view-dir, --eye, --look-at, and
// the shading and emission flags: name, value, group and help text, added to a command by
// addRenderFlags), and turning them into validated RenderSettings, the same way for every
// command that renders (a command that leaves a flag out never sees it: CLI11 refuses it).
#pragma once
#include <glm/glm.hpp>
#include <set>
#include <string>

#include "cli/args.h"
#include "render/settings.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace CLI {
class App;
}

namespace vdbsplat::cli {

/// @brief Declares every render flag on @p app except those named in @p leaveOut (flags a
/// command sets itself: animate's path places the camera, the study varies the mode, …).
void addRenderFlags(CLI::App& app, const std::set<std::string>& leaveOut = {});

/// @brief "X,Y,Z" → vector; @throw Error naming @p flag.
glm::dvec3 parseVec3(const std::string& text, const std::string& flag);

/// @brief The validated settings the render flags in @p args describe (defaults elsewhere).
/// --eye's look-at is resolved after the volume is loaded (resolveLookAt).
/// @throw Error naming the first bad flag.
RenderSettings settingsFromFlags(const Args& args);

/// @brief With --eye: the look-at from --look-at, or the centre of @p volume's bounds.
void resolveLookAt(const Args& args, const Volume& volume, RenderSettings& settings);

/// @brief The transfer function of settings.transferFunction; @throw Error "--tf: …".
TransferFunction transferFunctionFor(const RenderSettings& settings);

}  // namespace vdbsplat::cli
