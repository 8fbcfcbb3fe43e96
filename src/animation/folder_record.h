// animation/folder_record.h — what an animation folder's animation.json and reference.json
// fingerprint, and when --resume accepts a folder: the recorded settings equal today's, and
// the frame cameras hash (FNV-1a 64 of their descriptions) the same.
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

}  // namespace vdbsplat::animation
