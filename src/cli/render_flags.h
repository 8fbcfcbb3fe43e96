// cli/render_flags.h — the render flags shared by `vdbsplat render` and `vdbsplat animate`.
// Owns: turning --mode, --size, --tf, --grid, --fov, --distance, --threads, --spp,
// --threshold, --footprint, --filter-order, --subpixels, --lod, --simd, --show-primitives, --tables, --up,
// --view-dir, --eye, --look-at and the shading flags into validated RenderSettings, the same way for every command that renders
// (a command that does not declare a flag never sees it: Args refuses it first).
#pragma once
#include <glm/glm.hpp>
#include <set>
#include <string>

#include "cli/args.h"
#include "render/settings.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

/// The help lines of the flags that choose what is rendered and how (--grid, --mode, --size,
/// --kernel, --tf), one text for render and animate. A string-literal macro so each command's
/// help stays one literal.
#define VDBSPLAT_SCENE_FLAGS_HELP \
    "  --grid NAME        grid to render (default: the grid named density, else the first float or double grid)\n" \
    "  --mode MODE        hybrid (default) | splat | point | ewa | swan | none | reference\n" \
    "                     ewa: Zwicker et al. 2001 affine (Jacobian) splats + low-pass; swan: Swan et\n" \
    "                     al. 1997, minified footprints stretched to the pixel filter; none: no\n" \
    "                     low-pass (splats without it, points to the nearest pixel); ewa, swan and\n" \
    "                     none ignore --filter-order/--subpixels (docs/modes.md)\n" \
    "  --size WxH         image size in pixels (default 400x400)\n" \
    "  --kernel K         reconstruction kernel, every mode and the reference: gaussian (default,\n" \
    "                     s_g 0.65, R 2) | gaussian-sharp (s_g 0.5, R 1.55: less blur when\n" \
    "                     magnified, more ripple; docs/kernel.md)\n" \
    "  --tf PRESET|FILE   transfer function: grey (default), ct-bone, fire, or a JSON file\n"

namespace vdbsplat::cli {

/// The value flags settingsFromFlags() reads (without -o and command-specific ones).
const std::set<std::string>& renderValueFlags();

/// The shading flags (--shading, --ambient, --diffuse, --specular, --shininess, --light,
/// --gradient-opacity), part of renderValueFlags(); `bench` adds them to its own set.
const std::set<std::string>& shadingValueFlags();

/// Help lines for the shading flags, shared by render, animate and bench.
extern const char* const kShadingHelp;

/// The emission flags (--emission, --emission-map, --emission-scale, --kelvin), part of
/// renderValueFlags(); `bench` adds them to its own set.
const std::set<std::string>& emissionValueFlags();

/// Help lines for the emission flags (docs/emission.md), shared by render, animate and bench.
extern const char* const kEmissionHelp;

/// @brief The validated emission settings the emission flags in @p args describe.
/// @throw Error naming the first bad flag (a bad value, or a map flag without --emission).
EmissionSettings emissionFromFlags(const Args& args);

/// @brief The validated shading settings the shading flags in @p args describe.
/// @throw Error naming the first bad flag (a bad value, or a lighting flag without --shading).
ShadingSettings shadingFromFlags(const Args& args);

/// @brief "X,Y,Z" → vector; @throw Error naming @p flag.
glm::dvec3 parseVec3(const std::string& text, const std::string& flag);

/// @brief The validated settings the render flags in @p args describe (defaults elsewhere).
/// --eye's look-at is resolved after the volume is loaded (resolveLookAt).
/// @throw Error naming the first bad flag.
RenderSettings settingsFromFlags(const Args& args);

/// @brief --filter-order and --subpixels into @p s (render, animate and bench share it).
/// @throw Error naming the flag.
void applyFilterFlags(const Args& args, RenderSettings& s);

/// @brief With --eye: the look-at from --look-at, or the centre of @p volume's bounds.
void resolveLookAt(const Args& args, const Volume& volume, RenderSettings& settings);

/// @brief The transfer function of settings.transferFunction; @throw Error "--tf: …".
TransferFunction transferFunctionFor(const RenderSettings& settings);

}  // namespace vdbsplat::cli
