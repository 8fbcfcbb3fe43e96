// study/report.h — what a study measured and the files that publish it.
// Owns: the study's results (volume → kernel → view → reference and every mode, with image
// paths relative to the study folder), metrics.csv (one row per volume × kernel × view ×
// mode), metrics.json (the same rows and the study's settings), the PSNR/SSIM/time-against-
// zoom plots as inline SVG, and index.html: self-contained (CSS and SVG inline, no script or
// font from the network; the images by relative path), with an image grid per view (the
// reference and every mode, the error heat map of each under it with the colour bar, crops
// of the worst window at 4×), the metrics table, and a small inline script that counts the
// images that loaded into #selfcheck (what the end-to-end test reads back).
#pragma once
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "metrics/metrics.h"
#include "study/error_map.h"
#include "study/views.h"

namespace vdbsplat::study {

/// One forward mode at one view: its metrics against the view's reference, cost and pictures.
struct ModeResult {
    std::string mode;
    ImageMetrics metrics;
    double seconds = 0.0;  ///< render() wall time (from the run that made the image)
    uint64_t points = 0, splats = 0;
    std::string image, errorImage, cropImage;  ///< PNG paths relative to the study folder
};

struct ViewResult {
    View view;
    double referenceSeconds = 0.0;
    std::string referenceImage, referenceCrop;
    CropWindow crop;
    std::vector<ModeResult> modes;
};

struct KernelResult {
    std::string kernel;
    std::vector<ViewResult> views;
};

struct VolumeResult {
    std::string id;    ///< file-safe, the folder of its images
    std::string path;  ///< as given on the command line
    std::string grid;
    uint64_t activeVoxels = 0;
    std::string tf;  ///< its transfer function (preset or file)
    std::vector<KernelResult> kernels;
};

struct StudyResult {
    std::string command;  ///< the command line that made it
    int width = 0, height = 0, spp = 0;
    std::string tf;  ///< the transfer function of every volume, or "per volume"
    std::vector<std::string> modes, kernels;
    nlohmann::json settings;  ///< the shared render settings (RenderSettings::toJson, no mode or distance)
    std::vector<VolumeResult> volumes;
};

/// @brief The header of metrics.csv (no newline).
std::string csvHeader();
/// @brief metrics.csv: the header and one row per volume × kernel × view × mode; PSNR of
/// identical images is written "inf".
std::string metricsCsv(const StudyResult& study);
/// @brief metrics.json: {"study": settings…, "rows": [the CSV's rows as objects]} (PSNR
/// "inf" as null).
nlohmann::ordered_json metricsJson(const StudyResult& study);

/// A series of a plot: one line with markers; NaN values are left out.
struct Series {
    std::string name, colour;
    bool dashed = false;
    std::vector<double> x, y;
};

/// A line chart over a logarithmic x axis (zoom), linear or logarithmic y.
struct Plot {
    std::string title, xLabel, yLabel;
    bool logY = false;
    std::vector<Series> series;
    double yCap = std::numeric_limits<double>::infinity();  ///< linear axis: never above (SSIM: 1)
};

/// @brief The chart as an inline <svg class="plot"> element (axes, ticks, lines, legend).
std::string plotSvg(const Plot& plot);

/// @brief The colour bar of the heat maps as an inline <svg class="colourbar"> element.
std::string colourBarSvg();

/// @brief The whole index.html.
std::string reportHtml(const StudyResult& study);

/// @brief @p text with & < > " ' escaped for HTML text and attributes.
std::string htmlEscape(const std::string& text);

/// @brief The line colour of the @p i-th mode (a fixed palette, repeating).
std::string modeColour(size_t i);

}  // namespace vdbsplat::study
