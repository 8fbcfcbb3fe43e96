// shading/shading.cpp — settings, gradient and Blinn–Phong (see shading.h).
#include "shading/shading.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace vdbsplat {

namespace {

void checkUnit(float v, const char* flag) {
    if (!(std::isfinite(v) && v >= 0.f && v <= 1.f)) throw Error(std::string(flag) + ": must be a number in [0, 1]");
}

float smoothstep01(float t) {
    t = std::clamp(t, 0.f, 1.f);
    return t * t * (3.f - 2.f * t);
}

}  // namespace

ShadingSettings ShadingSettings::ctPreset() {
    ShadingSettings s;
    s.mode = ShadingMode::Phong;
    s.ambient = 0.25f;
    s.diffuse = 0.75f;
    s.specular = 0.35f;
    s.shininess = 24.f;
    return s;
}

void ShadingSettings::validate() const {
    checkUnit(ambient, "--ambient");
    checkUnit(diffuse, "--diffuse");
    checkUnit(specular, "--specular");
    if (!(std::isfinite(shininess) && shininess >= 1.f && shininess <= 1000.f))
        throw Error("--shininess: must be a number in [1, 1000]");
    if (hasLight) {
        const double n = glm::length(light);
        if (!(std::isfinite(n) && n > 1e-12)) throw Error("--light: must be a non-zero direction X,Y,Z");
    }
    if (!(std::isfinite(gradientOpacity) && gradientOpacity >= 0.f && gradientOpacity <= 1e6f))
        throw Error("--gradient-opacity: must be a number in [0, 1e6] (0 turns it off)");
}

nlohmann::json ShadingSettings::toJson() const {
    nlohmann::json j;
    j["mode"] = mode == ShadingMode::Phong ? "phong" : "off";
    j["ambient"] = ambient;
    j["diffuse"] = diffuse;
    j["specular"] = specular;
    j["shininess"] = shininess;
    if (hasLight) j["light"] = {light.x, light.y, light.z};
    else j["light"] = "headlight";
    j["gradient_opacity"] = gradientOpacity;
    return j;
}

glm::vec3 centralDifference(const float n[6]) {
    return 0.5f * glm::vec3(n[1] - n[0], n[3] - n[2], n[5] - n[4]);
}

float gradientOpacityFactor(float magnitude, float k) {
    return k > 0.f ? -std::expm1(-k * magnitude) : 1.f;
}

// Blinn 1977 ("Models of light reflection for computer synthesized pictures", eq. for the
// half-vector H = (L + E)/|L + E| and the specular term (N·H)^n), Phong 1975 (ambient +
// diffuse N·L + specular). The normal is the negated gradient (pointing from dense to less
// dense), turned to face the eye: a volume has no inside or outside, so both sides shade.
ShadingFactors shadeVoxel(const glm::vec3& worldGradient, float magnitude, const glm::vec3& toEye,
                          const glm::vec3& toLight, const ShadingSettings& s) {
    ShadingFactors f;
    const float weight = s.mode == ShadingMode::Phong ? smoothstep01(magnitude / kFullShadingGradient) : 0.f;
    const float length = glm::length(worldGradient);
    if (!(weight > 0.f) || !(length > 0.f)) return f;  // zero gradient: the unshaded colour
    glm::vec3 n = -worldGradient / length;
    if (glm::dot(n, toEye) < 0.f) n = -n;
    const float nl = glm::dot(n, toLight);
    float d = s.ambient, spec = 0.f;
    if (nl > 0.f) {
        d += s.diffuse * nl;
        const glm::vec3 h = toLight + toEye;
        const float hl = glm::length(h);
        if (hl > 0.f) spec = s.specular * std::pow(std::max(0.f, glm::dot(n, h) / hl), s.shininess);
    }
    f.diffuse = 1.f + weight * (d - 1.f);
    f.specular = weight * spec;
    return f;
}

}  // namespace vdbsplat
