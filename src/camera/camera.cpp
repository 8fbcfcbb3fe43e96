// camera/camera.cpp — pinhole camera construction and default framing.
#include "camera/camera.h"

#include <cmath>
#include <numbers>
#include <sstream>

#include "util/error.h"

namespace vdbsplat {

namespace {
/// Finite and small enough that lengths and cross products stay finite in double
/// (1e300 would overflow |v|² to inf and be misreported as "eye equals look-at").
constexpr double kMaxCoordinate = 1e15;
bool finite3(const glm::dvec3& v) {
    for (int i = 0; i < 3; ++i)
        if (!(std::isfinite(v[i]) && std::abs(v[i]) <= kMaxCoordinate)) return false;
    return true;
}
}  // namespace

Camera::Camera(const glm::dvec3& eye, const glm::dvec3& lookAt, const glm::dvec3& up,
               double fovDeg, int width, int height)
    : eye_(eye), lookAt_(lookAt), fovDeg_(fovDeg), width_(width), height_(height) {
    if (!finite3(eye)) throw Error("--eye: coordinates must be finite numbers of magnitude at most 1e15");
    if (!finite3(lookAt)) throw Error("--look-at: coordinates must be finite numbers of magnitude at most 1e15");
    if (!finite3(up)) throw Error("--up: coordinates must be finite numbers of magnitude at most 1e15");
    if (!(fovDeg > 0.0 && fovDeg < 170.0)) throw Error("--fov: must be in (0, 170) degrees");
    if (width < 1 || height < 1) throw Error("--size: image size must be at least 1x1");
    const glm::dvec3 view = lookAt - eye;
    const double len = glm::length(view);
    if (!(len > 1e-12 * std::max(1.0, glm::length(eye)))) throw Error("--eye: equals --look-at, no view direction");
    forward_ = view / len;
    if (!(glm::length(up) > 0.0)) throw Error("--up: must not be the zero vector");
    const glm::dvec3 r = glm::cross(forward_, glm::normalize(up));
    if (glm::length(r) < 1e-6) throw Error("--up: parallel to the view direction");
    right_ = glm::normalize(r);
    up_ = glm::cross(right_, forward_);
    focal_ = 0.5 * height / std::tan(0.5 * fovDeg * std::numbers::pi / 180.0);
    principal_ = {0.5 * width, 0.5 * height};
}

Camera Camera::cropped(int x0, int y0, int width, int height) const {
    if (width < 1 || height < 1) throw Error("camera crop: the rectangle is empty");
    Camera c = *this;
    c.width_ = width, c.height_ = height;
    c.principal_ = principal_ - PixelCoord(x0, y0);
    return c;
}

std::string Camera::describe() const {
    std::ostringstream s;
    s.precision(9);
    s << "eye " << eye_.x << "," << eye_.y << "," << eye_.z << " look-at " << lookAt_.x << "," << lookAt_.y << ","
      << lookAt_.z << " up " << up_.x << "," << up_.y << "," << up_.z << " fov " << fovDeg_ << " size " << width_ << "x"
      << height_;
    return s.str();
}

glm::dvec3 defaultViewDirection() { return glm::normalize(glm::dvec3(0.9, -1.3, 0.75)); }

Camera makeCamera(const CameraSpec& spec, const glm::dvec3& boxMin, const glm::dvec3& boxMax) {
    if (spec.hasEye) return Camera(spec.eye, spec.lookAt, spec.up, spec.fovDeg, spec.width, spec.height);
    if (!(std::isfinite(spec.distance) && spec.distance > 0.0)) throw Error("--distance: must be a positive number");
    if (!(spec.fovDeg > 0.0 && spec.fovDeg < 170.0)) throw Error("--fov: must be in (0, 170) degrees");
    const glm::dvec3 centre = 0.5 * (boxMin + boxMax);
    const double radius = std::max(0.5 * glm::length(boxMax - boxMin), 1e-9);
    // The smaller of the vertical and horizontal fields of view.
    const double halfV = 0.5 * spec.fovDeg * std::numbers::pi / 180.0;
    const double halfH = std::atan(std::tan(halfV) * spec.width / double(spec.height));
    const double half = std::min(halfV, halfH);
    // The bounding sphere's silhouette spans 80% of that field: sin(0.8·half) = radius / D.
    const double framing = radius / std::sin(0.8 * half);
    glm::dvec3 direction = defaultViewDirection();
    if (spec.hasViewDir) {
        const double length = glm::length(spec.viewDir);
        if (!(std::isfinite(length) && length > 0.0 && length < 1e300))
            throw Error("--view-dir: must be a finite, non-zero direction");
        direction = spec.viewDir / length;
    }
    const glm::dvec3 eye = centre + direction * (framing * spec.distance);
    return Camera(eye, centre, spec.up, spec.fovDeg, spec.width, spec.height);
}

}  // namespace vdbsplat
