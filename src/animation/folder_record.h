// animation/folder_record.h — what an animation folder's animation.json and reference.json
// fingerprint, and when --resume accepts a folder: the recorded settings equal today's, and
// the frame cameras hash (FNV-1a 64 of their descriptions) the same; olderBuildsRecord tells a
// folder of an older build, which left out settings at their (then) defaults.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace vdbsplat::animation {

/// @brief The frame cameras' fingerprint: FNV-1a 64 (hex) of their descriptions, one per line.
std::string cameraFingerprint(const std::string& cameraText);

/// @brief True if @p old, a folder's record, describes the animation of @p record (whose
/// "cameras_fnv1a" is cameraFingerprint(@p cameraText)): equal, or equal but for the camera
/// fingerprint that folders written before session 6 hold (a mistyped FNV offset basis, a digit
/// short) over the same cameras.
bool sameAnimation(const nlohmann::json& old, nlohmann::json record, const std::string& cameraText);

/// @brief True if @p old, a folder's record that sameAnimation() rejects, would match @p record
/// without the settings that older builds wrote only away from their defaults
/// (RenderSettings::kIdentityOnlyKeys) and that @p old lacks: a folder of
/// the same animation made by a build whose defaults may have been other (--cutoff: 1e-4 until
/// session 40), which --resume refuses with its own message.
bool olderBuildsRecord(const nlohmann::json& old, nlohmann::json record, const std::string& cameraText);

}  // namespace vdbsplat::animation
