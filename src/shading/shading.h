// shading/shading.h — gradient-based Blinn–Phong shading of the classified voxels.
// Owns: ShadingSettings (--shading off|phong|ct, --ambient, --diffuse, --specular,
// --shininess, --light, --gradient-opacity: validated, echoed into JSON), the per-voxel
// gradient (central differences of the normalised values in index space) and the lighting
// model: Blinn 1977's half-vector form of Phong 1975,
//     D = k_a + k_d·max(0, n·l),   S = k_s·max(0, n·h)^p  (only where n·l > 0),
// with h = (l + v)/|l + v| and n turned to face the viewer (two-sided). A voxel's shaded
// colour is c·D + S (white light); ShadingFactors carries (D, S) and the gradient-opacity
// factor G that scales its extinction. docs/shading.md gives the definitions and the reasons.
#pragma once
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>

namespace vdbsplat {

enum class ShadingMode { Off, Phong };

/// Gradient magnitude (normalised value per voxel) from which a voxel is fully shaded; below
/// it the shading fades smoothly to the unshaded colour (D = 1, S = 0 at zero gradient), so
/// flat regions keep their colour and noise-level gradients give no speckle. 0.01 is about
/// 2.5 uint8 levels per voxel: scanner noise in the Engine and Bonsai interiors is larger.
inline constexpr float kFullShadingGradient = 0.01f;

struct ShadingSettings {
    ShadingMode mode = ShadingMode::Off;
    float ambient = 0.3f;      ///< k_a ∈ [0, 1]
    float diffuse = 0.7f;      ///< k_d ∈ [0, 1]
    float specular = 0.2f;     ///< k_s ∈ [0, 1]
    float shininess = 20.f;    ///< p ∈ [1, 1000]
    bool hasLight = false;     ///< false: a headlight (light at the eye)
    glm::dvec3 light{0.0};     ///< directional light: world direction from the volume towards the light
    float gradientOpacity = 0.f;  ///< K ≥ 0: σ' = σ·(1 − exp(−K·|∇|)); 0: off

    /// @brief The "ct" preset: phong with values tuned on the Engine and Bonsai (docs/shading.md).
    static ShadingSettings ctPreset();
    /// True when a shading pass is needed (lighting or gradient opacity).
    bool active() const { return mode != ShadingMode::Off || gradientOpacity > 0.f; }
    /// @throw Error naming the flag of the first invalid value.
    void validate() const;
    nlohmann::json toJson() const;
};

/// @brief What shading does to one voxel: colour c → c·diffuse + specular, σ → σ·opacity.
struct ShadingFactors {
    float diffuse = 1.f;   ///< D (ambient + diffuse term, blended towards 1 at small gradients)
    float specular = 0.f;  ///< S (added to every channel)
    float opacity = 1.f;   ///< G (gradient-opacity factor)
};

/// @brief Central difference ∇x ≈ (x(i+1) − x(i−1))/2 per axis, in normalised value per voxel,
/// from the six neighbours' normalised values (−x, +x, −y, +y, −z, +z).
glm::vec3 centralDifference(const float neighbours[6]);

/// @brief Blinn–Phong at one voxel. @p worldGradient: the gradient in world space (any
/// scale; only its direction is used), @p magnitude: |∇| in normalised value per voxel,
/// @p toEye: unit vector from the voxel to the eye, @p toLight: unit vector to the light.
ShadingFactors shadeVoxel(const glm::vec3& worldGradient, float magnitude, const glm::vec3& toEye,
                          const glm::vec3& toLight, const ShadingSettings& s);

/// @brief The gradient-opacity factor 1 − exp(−K·|∇|) (1 when K = 0).
float gradientOpacityFactor(float magnitude, float k);

}  // namespace vdbsplat
