// animation/folder_record.cpp — see folder_record.h.
#include "animation/folder_record.h"

#include "render/settings.h"
#include "util/fnv1a.h"

namespace vdbsplat::animation {
namespace {
constexpr uint64_t kLegacyCameraBasis = 1469598103934665603ull;  // 14695981039346656037 without its last digit
}

std::string cameraFingerprint(const std::string& cameraText) { return fnv1aHex(cameraText); }

bool sameAnimation(const nlohmann::json& old, nlohmann::json record, const std::string& cameraText) {
    if (old == record) return true;
    record["cameras_fnv1a"] = fnv1aHex(cameraText, kLegacyCameraBasis);
    return old == record;
}

bool olderBuildsRecord(const nlohmann::json& old, nlohmann::json record, const std::string& cameraText) {
    if (!old.contains("settings") || !old["settings"].is_object() || !record.contains("settings")) return false;
    bool lacks = false;
    for (const char* key : RenderSettings::kIdentityOnlyKeys)
        if (!old["settings"].contains(key) && record["settings"].contains(key)) record["settings"].erase(key), lacks = true;
    return lacks && sameAnimation(old, std::move(record), cameraText);
}

}  // namespace vdbsplat::animation
