// camera/camera.h — the pinhole camera every mode shares.
// Owns: the world → view → pixel maps, pixel rays, and the default framing of a
// bounding box. View space: eye at the origin, x right, y up, z forward (depth
// z > 0 in front of the eye). Pixel space: x right, y down, pixel (i, j) covers
// [i, i+1) × [j, j+1), its centre is (i + 0.5, j + 0.5).
#pragma once
#include <cmath>
#include <glm/glm.hpp>
#include <string>

namespace vdbsplat {

using WorldPoint = glm::dvec3;  ///< a position in world space
using ViewPoint = glm::dvec3;   ///< a position in view space (eye at origin, +z forward)
using PixelCoord = glm::dvec2;  ///< continuous pixel coordinates (y down)

/// @brief What the user asks for; turned into a Camera by makeCamera().
struct CameraSpec {
    int width = 400;
    int height = 400;
    double fovDeg = 30.0;           ///< vertical field of view
    bool hasEye = false;            ///< false: frame the bounding box (see frameBox)
    glm::dvec3 eye{0.0}, lookAt{0.0}, up{0.0, 0.0, 1.0};
    double distance = 1.0;          ///< multiplies the framing distance (8 far, 1 framed, 0.35 close)
    bool hasViewDir = false;        ///< framing: false uses defaultViewDirection()
    glm::dvec3 viewDir{0.0};        ///< framing: direction from the box centre to the eye (any length)
};

class Camera {
public:
    /// @brief A camera at @p eye looking at @p lookAt.
    /// @throw Error when eye == lookAt, up is parallel to the view direction,
    /// the fov is outside (0, 170) degrees, the size is not positive, or any value is not finite.
    Camera(const glm::dvec3& eye, const glm::dvec3& lookAt, const glm::dvec3& up,
           double fovDeg, int width, int height);

    ViewPoint toView(const WorldPoint& p) const {
        const glm::dvec3 d = p - eye_;
        return {glm::dot(d, right_), glm::dot(d, up_), glm::dot(d, forward_)};
    }
    /// @brief Perspective projection of a view point with z > 0 to pixel coordinates.
    PixelCoord project(const ViewPoint& v) const {
        return {principal_.x + focal_ * v.x / v.z, principal_.y - focal_ * v.y / v.z};
    }
    /// @brief View-space direction (not normalised, z = 1) of the ray through pixel coordinate @p p.
    glm::dvec3 viewRay(const PixelCoord& p) const {
        return {(p.x - principal_.x) / focal_, -(p.y - principal_.y) / focal_, 1.0};
    }
    /// @brief World-space unit direction of the ray through pixel coordinate @p p.
    glm::dvec3 worldRay(const PixelCoord& p) const {
        const glm::dvec3 v = viewRay(p);
        return glm::normalize(v.x * right_ + v.y * up_ + v.z * forward_);
    }
    /// @brief A view-space direction rotated back to world space.
    glm::dvec3 viewToWorldDir(const glm::dvec3& v) const { return v.x * right_ + v.y * up_ + v.z * forward_; }

    const glm::dvec3& eye() const { return eye_; }
    const glm::dvec3& forward() const { return forward_; }
    const glm::dvec3& right() const { return right_; }
    const glm::dvec3& up() const { return up_; }
    const glm::dvec3& lookAt() const { return lookAt_; }
    double focal() const { return focal_; }        ///< focal length f in pixels
    /// A world @p length at view depth @p z in pixels, length·f/z (+∞ at or behind the eye plane):
    /// a voxel's projected spacing, as the projection and the compositor's rebuilds take it.
    double spacingPx(double length, double z) const { return z > 0.0 ? length * focal_ / z : INFINITY; }
    PixelCoord principal() const { return principal_; }
    int width() const { return width_; }
    int height() const { return height_; }
    double fovDeg() const { return fovDeg_; }
    /// @brief The same camera (eye, axes, focal length) seeing only the pixels
    /// [@p x0, @p x0 + @p width) × [@p y0, @p y0 + @p height) of this one: pixel (x, y) of the
    /// crop is pixel (x0 + x, y0 + y) here (the principal point moves by (−x0, −y0)).
    /// @throw Error when the crop is empty.
    Camera cropped(int x0, int y0, int width, int height) const;
    /// @brief One line describing the camera (for EXR metadata and stats).
    std::string describe() const;

private:
    glm::dvec3 eye_, lookAt_, forward_, right_, up_;
    double focal_, fovDeg_;
    PixelCoord principal_;
    int width_, height_;
};

/// @brief The fixed oblique direction (from the target towards the eye) of the default framing.
glm::dvec3 defaultViewDirection();

/// @brief Builds the camera for @p spec; without an eye it frames the world box
/// [@p boxMin, @p boxMax] from defaultViewDirection() so that its bounding sphere fills
/// about 80% of the smaller image side, at spec.distance times that framing distance.
/// @throw Error for an invalid spec (see Camera).
Camera makeCamera(const CameraSpec& spec, const glm::dvec3& boxMin, const glm::dvec3& boxMax);

}  // namespace vdbsplat
