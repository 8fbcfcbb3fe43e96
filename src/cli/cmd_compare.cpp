// cli/cmd_compare.cpp — `vdbsplat compare IMAGE REFERENCE [--json FILE]`.
// Owns: reading the two images, printing one line of metrics (metrics/metrics.h
// defines them: sRGB display values over black), and the optional JSON report,
// written atomically (temporary file, then rename).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "image/image.h"
#include "metrics/metrics.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vdbsplat::cli {

namespace {

/// Reads an image, keeping any error on one line and naming the file.
Image readChecked(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
    try {
        return readImage(path);
    } catch (const Error& e) {
        std::string what = e.what();
        for (char& c : what)
            if (c == '\n' || c == '\r') c = ' ';
        throw Error(what);
    }
}

std::string formatPsnr(double psnr) {
    if (std::isinf(psnr)) return "inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", psnr);
    return buf;
}

std::string summaryLine(const ImageMetrics& m, const Image& image) {
    std::ostringstream line;
    line << "psnr=" << formatPsnr(m.psnr) << " dB rmse=" << m.rmse << " mse=" << m.mse
         << " max_abs=" << m.maxAbsError << " ssim=" << m.ssim << " size=" << sizeText(image);
    if (m.nonFinitePixels) line << " nan_pixels=" << m.nonFinitePixels;
    return line.str();
}

nlohmann::ordered_json report(const ImageMetrics& m, const Image& image, const std::string& a, const std::string& b) {
    nlohmann::ordered_json j;
    j["image"] = a;
    j["reference"] = b;
    j["width"] = image.width;
    j["height"] = image.height;
    j["mse"] = m.mse;
    j["rmse"] = m.rmse;
    j["psnr_db"] = std::isinf(m.psnr) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(m.psnr);
    j["identical"] = m.mse == 0.0;
    j["max_abs_error"] = m.maxAbsError;
    j["ssim"] = m.ssim;
    j["nan_pixels"] = m.nonFinitePixels;
    j["space"] = "srgb-display-over-black";
    return j;
}

}  // namespace

void declareCompare(CLI::App& app) {
    app.description(
        "image metrics (PSNR, RMSE, SSIM) of an image against a reference\n"
        "\n"
        "usage: vdbsplat compare IMAGE REFERENCE [--json FILE]\n"
        "\n"
        "Image metrics of IMAGE against REFERENCE (PNG or EXR, same size), on sRGB display\n"
        "values in [0, 1] over black (alpha ignored): MSE, RMSE, PSNR (dB, peak 1; 'inf' when\n"
        "identical), max abs error over R, G, B, and SSIM on luma (11x11 Gaussian window).\n"
        "Prints one line; --json FILE also writes them as JSON (PSNR null when identical).");
    addPositional(app, "IMAGE", "the image to measure (PNG or EXR)");
    addPositional(app, "REFERENCE", "the image it is measured against, of the same size");
    addValueFlag(app, "--json", "FILE", "also write the metrics as JSON");
}

int runCompare(const Args& args) {
    const auto& pos = args.positionals();
    if (pos.size() != 2)
        throw Error("compare needs IMAGE and REFERENCE, got " + std::to_string(pos.size()) + " file(s) (see --help)");
    if (const auto json = args.get("--json")) {
        checkOutputPath(*json);
        for (const std::string& input : pos) checkNotAnInput(*json, input, "--json");
    }
    const Image image = readChecked(pos[0]);
    const Image reference = readChecked(pos[1]);
    if (image.width != reference.width || image.height != reference.height)
        throw Error(pos[0] + " (" + sizeText(image) + ") and " + pos[1] + " (" + sizeText(reference) +
                    ") differ in size");
    const ImageMetrics m = compareImages(image, reference);
    if (const auto json = args.get("--json")) writeTextFileAtomic(*json, report(m, image, pos[0], pos[1]).dump() + "\n");
    std::cout << summaryLine(m, image) << "\n";
    return 0;
}

}  // namespace vdbsplat::cli
