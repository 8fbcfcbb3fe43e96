// metrics/metrics.h — image-quality metrics of an image against a reference.
// Owns: MSE, RMSE, PSNR, max abs error and SSIM as a library (tests, `vdbsplat
// compare`, the benchmark). Images are compared as people see them: each
// premultiplied linear RGB pixel is taken over black (alpha is ignored) and
// sRGB-encoded to display values in [0, 1] (clamped, in double: displayValue), then
//   MSE  = mean over pixels and R, G, B of (a − b)²,  RMSE = √MSE,
//   PSNR = 10·log10(1 / MSE) dB (peak 1; +inf for identical display values),
//   max abs error = max over pixels and R, G, B of |a − b|,
//   SSIM = Wang et al. 2004 on luma Y' = 0.2126 R' + 0.7152 G' + 0.0722 B' of the
//          display values: 11×11 Gaussian window (σ = 1.5), K1 = 0.01, K2 = 0.03,
//          L = 1, evaluated at every pixel (windows truncated at the border and
//          renormalised) and averaged.
// NaN channels count in nonFinitePixels and are compared as black (0); ±inf clamp.
#pragma once
#include <cstdint>
#include <string>

#include "image/image.h"

namespace vdbsplat {

/// @brief Every metric of one comparison (display values in [0, 1]).
struct ImageMetrics {
    double mse = 0.0;          ///< mean squared error over R, G, B
    double rmse = 0.0;         ///< √mse
    double psnr = 0.0;         ///< dB, peak 1; +infinity when mse == 0
    double maxAbsError = 0.0;  ///< largest |a − b| over pixels and R, G, B
    double ssim = 1.0;         ///< mean SSIM on luma, in [−1, 1]; 1 for identical images
    uint64_t nonFinitePixels = 0;  ///< pixels with a NaN channel in either image (compared as black)
};

/// @brief The display value of one linear channel: over black, clamped to [0, 1] and
/// sRGB-encoded in double precision (exactly 0 at 0 and 1 at 1); NaN → 0.
double displayValue(float linear);

/// @brief PSNR in dB of a mean squared error with peak 1: 10·log10(1 / mse); +inf for mse == 0.
double psnrFromMse(double mse);

/// @brief Compares @p image with @p reference (see the file comment for the definitions).
/// @throw Error "image sizes differ: WxH vs WxH" when the sizes differ, or when either is empty.
ImageMetrics compareImages(const Image& image, const Image& reference);

/// @brief Mean SSIM on display luma (see the file comment).
/// @throw Error as compareImages.
double ssim(const Image& image, const Image& reference);

/// @brief "WxH" of an image, for messages.
std::string sizeText(const Image& image);

}  // namespace vdbsplat
