// animation/frame_stats.h — what `vdbsplat animate` measures per frame, and how it is reported.
// Owns: the temporal metric (flicker), the per-frame record and its CSV row (written and read
// back, so --resume keeps the rows of frames it skips), the frames marked as point/splat
// switches, and the self-contained SVG plot of PSNR and flicker per frame.
//
// Flicker of frame t against a reference sequence R (display values as metrics.h defines them:
// premultiplied linear RGB over black, clamped, sRGB-encoded):
//     F_t = mean over pixels and R, G, B of |(I_t − I_{t−1}) − (R_t − R_{t−1})|
// — the frame-to-frame change the reference does not have, seen as shimmer or popping.
// It is 0 when I and R differ by a constant, and undefined for the first frame.
//
// Switch frames (marked in the plot and the CSV's `switch` column): frame t is marked when the
// splat fraction s = splats / (points + splats) crosses one half between t−1 and t
// (s_{t−1} < 0.5 ≤ s_t or s_t < 0.5 ≤ s_{t−1}: "cross"), or else changes by more than
// 0.10 (ten points of the fraction: "step") — where voxels move between points and splats.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"

namespace vdbsplat::animation {

/// @brief F_t (see the file comment). @throw Error when the four sizes differ or are empty.
double flicker(const Image& current, const Image& previous, const Image& referenceCurrent,
               const Image& referencePrevious);

/// One row of frames.csv.
struct FrameRecord {
    long long frame = 0;
    double time = 0.0;          ///< keyframe time (s); the frame index for zoom and orbit
    double distance = 0.0;      ///< framing distance (zoom, orbit); NaN for keyframes
    double eye[3] = {0, 0, 0};  ///< world eye of the frame
    double fov = 0.0;
    double seconds = 0.0;       ///< render() of the frame
    unsigned long long points = 0, splats = 0;
    double splatFraction = 0.0;
    std::optional<double> psnr;            ///< against the reference frame (--reference)
    std::optional<double> flicker;         ///< F_t (--reference, from the second frame)
    std::optional<double> referenceSeconds;
    std::string marker;                    ///< "", "cross" or "step" (see file comment)
};

/// @brief The CSV header line (no newline) for runs with or without --reference.
std::string csvHeader(bool reference);
/// @brief One CSV row (no newline); empty fields for absent values.
std::string csvRow(const FrameRecord& r, bool reference);
/// @brief Parses a row csvRow wrote; std::nullopt when it does not parse.
std::optional<FrameRecord> parseCsvRow(const std::string& line, bool reference);

/// @brief Sets each record's marker from the splat fractions (records in frame order).
void markSwitches(std::vector<FrameRecord>& records);

/// @brief A self-contained SVG: PSNR (left axis) and flicker (right axis) per frame as
/// polylines, splat fraction as a thin line, switch frames as vertical lines, with a legend.
std::string plotSvg(const std::vector<FrameRecord>& records, const std::string& title);

}  // namespace vdbsplat::animation
