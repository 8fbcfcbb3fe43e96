// animation/camera_path.h — camera paths for `vdbsplat animate`.
// Owns: the maths of the three built-in paths, and nothing about files or rendering:
//   zoom      — framing distances from K0 to K1 spaced geometrically (d_i = K0·(K1/K0)^(i/(N−1)),
//               both ends hit; equal zoom factor between neighbouring frames);
//   orbit     — the eye rotated about the up axis through the look-at point by DEG·i/N
//               (so a 360° orbit loops without repeating its first frame; the radius is constant);
//   keyframes — {eye, look_at, up, fov, time} keys read from JSON (strictly, bounded) and
//               interpolated by a cubic Hermite spline in time: Catmull–Rom tangents for
//               non-uniform knots, m_k = (p_{k+1} − p_{k−1}) / (t_{k+1} − t_{k−1}), one-sided at
//               the ends, on eye, look-at and up (up normalised after); monotone cubic
//               (Fritsch–Carlson) on fov so it never leaves the range of its neighbouring keys.
//               The curve passes through every key and is C¹ in time.
#pragma once
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace vdbsplat::animation {

/// Frame counts above this are refused as absurd (a typo, not an animation).
constexpr long long kMaxFrames = 100000;
/// Keyframe files larger than this are refused before parsing.
constexpr size_t kMaxPathFileBytes = 16u << 20;
/// JSON nesting deeper than this ([ { "eye": [ … ] } ] is 3) is refused before parsing.
constexpr int kMaxPathNesting = 4;

/// One camera key (world coordinates) at a time in seconds.
struct CameraKey {
    glm::dvec3 eye{0.0}, lookAt{0.0}, up{0.0, 0.0, 1.0};
    double fovDeg = 30.0;
    double time = 0.0;
};

/// @brief Distances of a geometric zoom from @p from to @p to in @p frames frames (both ends hit;
/// one frame: @p from). @throw Error naming --from/--to/--frames for non-positive or non-finite input.
std::vector<double> zoomDistances(double from, double to, long long frames);

/// @brief Eyes of an orbit: @p eye rotated about the axis through @p centre along @p up by
/// degrees·i/frames for i = 0 … frames−1 (right-handed about @p up).
/// @throw Error for a zero up axis or frames < 1.
std::vector<glm::dvec3> orbitEyes(const glm::dvec3& centre, const glm::dvec3& eye, const glm::dvec3& up,
                                  double degrees, long long frames);

/// @brief Parses a keyframe file's text: a JSON array of objects with "eye" and "look_at"
/// ([x, y, z]), "time" (seconds, strictly increasing, finite), and optionally "up" ([x, y, z],
/// default @p defaultUp) and "fov" (degrees in (0, 170), default @p defaultFov). Unknown keys,
/// wrong types, non-finite numbers, an empty list, nesting deeper than kMaxPathNesting are refused.
/// @throw Error "<name>: …" (one line) for anything malformed.
std::vector<CameraKey> parseKeyframes(const std::string& text, const std::string& name,
                                      const glm::dvec3& defaultUp, double defaultFov);

/// @brief Reads and parses @p path (at most kMaxPathFileBytes). @throw Error naming the file.
std::vector<CameraKey> loadKeyframes(const std::string& path, const glm::dvec3& defaultUp, double defaultFov);

/// @brief The interpolated camera at time @p t (clamped to the keys' time range).
CameraKey interpolate(const std::vector<CameraKey>& keys, double t);

/// @brief Frame times: @p frames uniformly spaced from the first to the last key's time (both
/// included; one frame: the first time). @throw Error naming --frames when out of range.
std::vector<double> uniformTimes(const std::vector<CameraKey>& keys, long long frames);

/// @brief Frame times at @p fps frames per second from the first key's time up to the last's:
/// t_i = t_0 + i / fps. @throw Error naming --fps when the rate or the resulting count is out of range.
std::vector<double> timesAtRate(const std::vector<CameraKey>& keys, double fps);

}  // namespace vdbsplat::animation
