// study/error_map.h — the pictures a study derives from its renders: error heat maps and crops.
// Owns: the per-pixel error e = mean over R, G, B of |a − r| in display values (metrics.h:
// premultiplied linear RGB over black, clamped, sRGB-encoded), its colour on a logarithmic
// scale from kHeatLow (darkest) to kHeatHigh (brightest; larger errors clamp) through a
// viridis-like ramp (the same scale for every mode and view, so maps compare at a glance),
// and the crop window: the square where the modes' summed error is largest.
#pragma once
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "image/image.h"

namespace vdbsplat::study {

/// Error (display units) at the bottom and the top of the heat map's scale: 1e-3 is below what
/// an 8-bit display shows (1/255 ≈ 4e-3); 0.3 is a third of full scale, a gross error.
inline constexpr double kHeatLow = 1e-3, kHeatHigh = 0.3;

/// @brief Position in [0, 1] of error @p e on the logarithmic scale (0 at or below kHeatLow,
/// 1 at or above kHeatHigh; NaN → 1).
double heatPosition(double e);

/// @brief The ramp's display colour (sRGB in [0, 1]) at position @p t in [0, 1] (clamped).
glm::dvec3 heatColour(double t);

/// @brief The ramp as "#rrggbb" at @p t (for the colour bar's SVG gradient).
std::string heatHex(double t);

/// @brief Per-pixel display error of @p image against @p reference (see the file comment).
/// @throw Error "image sizes differ …" as compareImages.
std::vector<double> pixelErrors(const Image& image, const Image& reference);

/// @brief The heat map of @p errors (width × height values) as an image writeImage stores
/// with the ramp's colours (opaque).
Image heatMap(const std::vector<double>& errors, int width, int height);

/// A square of the image, pixels [x, x + size) × [y, y + size).
struct CropWindow {
    int x = 0, y = 0, size = 0;
};

/// @brief Side of the crop for a width × height image: a quarter of the shorter side, at least
/// 8 pixels (the whole shorter side for smaller images).
int cropSide(int width, int height);

/// @brief The window of side cropSide() whose summed @p errors (one array per mode, each
/// width × height) is largest, searched on a grid of half-window steps (ties: the first, top
/// left first); the image centre when there is no error at all.
CropWindow worstWindow(const std::vector<std::vector<double>>& errors, int width, int height);

/// @brief The pixels of @p window in @p image. @throw Error when the window leaves the image.
Image crop(const Image& image, const CropWindow& window);

}  // namespace vdbsplat::study
