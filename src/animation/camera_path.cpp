// animation/camera_path.cpp — zoom, orbit and keyframe paths (see camera_path.h).
#include "animation/camera_path.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat::animation {

namespace {

void checkFrames(long long frames, const std::string& flag) {
    if (frames < 1 || frames > kMaxFrames)
        throw Error(flag + ": must be in 1.." + std::to_string(kMaxFrames) + ", got " + std::to_string(frames));
}

std::string where(const std::string& name, size_t k) { return name + ": keyframe " + std::to_string(k); }

double number(const nlohmann::json& v, const std::string& context) {
    if (!v.is_number()) throw Error(context + ": expected a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > 1e15) throw Error(context + ": must be a finite number of magnitude at most 1e15");
    return d;
}

glm::dvec3 vec3(const nlohmann::json& v, const std::string& context) {
    if (!v.is_array() || v.size() != 3) throw Error(context + ": expected an array of 3 numbers");
    return {number(v[0], context), number(v[1], context), number(v[2], context)};
}

/// Catmull–Rom tangent for non-uniform knots (one-sided at the ends).
template <class T>
T tangent(const std::vector<T>& p, const std::vector<double>& t, size_t k) {
    const size_t n = p.size();
    if (n < 2) return T(0.0);
    if (k == 0) return (p[1] - p[0]) / (t[1] - t[0]);
    if (k == n - 1) return (p[n - 1] - p[n - 2]) / (t[n - 1] - t[n - 2]);
    return (p[k + 1] - p[k - 1]) / (t[k + 1] - t[k - 1]);
}

template <class T>
T hermite(const T& p0, const T& p1, const T& m0, const T& m1, double h, double s) {
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * h * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * h * m1;
}

/// Fritsch–Carlson monotone tangents of a scalar sequence.
std::vector<double> monotoneTangents(const std::vector<double>& y, const std::vector<double>& t) {
    const size_t n = y.size();
    std::vector<double> m(n, 0.0);
    if (n < 2) return m;
    std::vector<double> d(n - 1);
    for (size_t k = 0; k + 1 < n; ++k) d[k] = (y[k + 1] - y[k]) / (t[k + 1] - t[k]);
    m[0] = d[0];
    m[n - 1] = d[n - 2];
    for (size_t k = 1; k + 1 < n; ++k) m[k] = (d[k - 1] * d[k] <= 0.0) ? 0.0 : 0.5 * (d[k - 1] + d[k]);
    for (size_t k = 0; k + 1 < n; ++k) {
        if (d[k] == 0.0) {
            m[k] = m[k + 1] = 0.0;
            continue;
        }
        const double a = m[k] / d[k], b = m[k + 1] / d[k], r = a * a + b * b;
        if (r > 9.0) {
            const double tau = 3.0 / std::sqrt(r);
            m[k] = tau * a * d[k];
            m[k + 1] = tau * b * d[k];
        }
    }
    return m;
}

}  // namespace

std::vector<double> zoomDistances(double from, double to, long long frames) {
    if (!(std::isfinite(from) && from > 0.0 && from < 1e6)) throw Error("--from: must be a positive number below 1e6");
    if (!(std::isfinite(to) && to > 0.0 && to < 1e6)) throw Error("--to: must be a positive number below 1e6");
    checkFrames(frames, "--frames");
    std::vector<double> d(static_cast<size_t>(frames));
    for (long long i = 0; i < frames; ++i)
        d[size_t(i)] = frames == 1 ? from : from * std::pow(to / from, double(i) / double(frames - 1));
    if (frames > 1) d.back() = to;  // exactly, whatever pow rounds to
    return d;
}

std::vector<glm::dvec3> orbitEyes(const glm::dvec3& centre, const glm::dvec3& eye, const glm::dvec3& up,
                                  double degrees, long long frames) {
    checkFrames(frames, "--frames");
    if (!std::isfinite(degrees) || std::abs(degrees) > 36000.0) throw Error("--orbit: must be a finite angle in degrees (at most 36000)");
    const double len = glm::length(up);
    if (!(len > 0.0 && std::isfinite(len))) throw Error("--up: must be a finite, non-zero vector");
    const glm::dvec3 axis = up / len;
    const glm::dvec3 r = eye - centre;
    const glm::dvec3 along = glm::dot(r, axis) * axis, across = r - along, side = glm::cross(axis, across);
    std::vector<glm::dvec3> eyes(static_cast<size_t>(frames));
    for (long long i = 0; i < frames; ++i) {
        const double a = degrees * std::numbers::pi / 180.0 * double(i) / double(frames);
        eyes[size_t(i)] = centre + along + std::cos(a) * across + std::sin(a) * side;  // Rodrigues
    }
    return eyes;
}

std::vector<CameraKey> parseKeyframes(const std::string& text, const std::string& name, const glm::dvec3& defaultUp,
                                      double defaultFov) {
    if (text.size() > kMaxPathFileBytes)
        throw Error(name + ": larger than " + std::to_string(kMaxPathFileBytes >> 20) + " MB, not a keyframe file");
    if (jsonNestingPastLimit(text, kMaxPathNesting) != std::string::npos)
        throw Error(name + ": JSON nested deeper than " + std::to_string(kMaxPathNesting) +
                    " levels (expected [ {\"eye\": [x, y, z], …}, … ])");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        std::string what = e.what();
        if (const size_t p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);  // drop "[json.exception…]"
        throw Error(name + ": not valid JSON: " + what);
    }
    if (!j.is_array()) throw Error(name + ": expected a JSON array of keyframes, got " + std::string(j.type_name()));
    if (j.empty()) throw Error(name + ": no keyframes");
    std::vector<CameraKey> keys;
    keys.reserve(j.size());
    for (size_t k = 0; k < j.size(); ++k) {
        const nlohmann::json& o = j[k];
        const std::string at = where(name, k);
        if (!o.is_object()) throw Error(at + ": expected an object, got " + std::string(o.type_name()));
        for (const auto& item : o.items())
            if (item.key() != "eye" && item.key() != "look_at" && item.key() != "up" && item.key() != "fov" &&
                item.key() != "time")
                throw Error(at + ": unknown key '" + item.key() + "' (expected eye, look_at, up, fov, time)");
        for (const char* required : {"eye", "look_at", "time"})
            if (!o.contains(required)) throw Error(at + ": missing \"" + required + "\"");
        CameraKey key;
        key.eye = vec3(o["eye"], at + ": eye");
        key.lookAt = vec3(o["look_at"], at + ": look_at");
        key.up = o.contains("up") ? vec3(o["up"], at + ": up") : defaultUp;
        key.fovDeg = o.contains("fov") ? number(o["fov"], at + ": fov") : defaultFov;
        key.time = number(o["time"], at + ": time");
        if (!(key.fovDeg > 0.0 && key.fovDeg < 170.0)) throw Error(at + ": fov must be in (0, 170) degrees");
        if (glm::length(key.up) == 0.0) throw Error(at + ": up must not be the zero vector");
        if (glm::length(key.eye - key.lookAt) == 0.0) throw Error(at + ": eye equals look_at");
        if (!keys.empty() && !(key.time > keys.back().time))
            throw Error(at + ": time " + std::to_string(key.time) + " is not after the previous key's " +
                        std::to_string(keys.back().time) + " (times must increase)");
        keys.push_back(key);
    }
    return keys;
}

std::vector<CameraKey> loadKeyframes(const std::string& path, const glm::dvec3& defaultUp, double defaultFov) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such file");
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path + ": cannot read: " + ec.message());
    if (size > kMaxPathFileBytes)
        throw Error(path + ": larger than " + std::to_string(kMaxPathFileBytes >> 20) + " MB, not a keyframe file");
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    if (!in && !in.eof()) throw Error(path + ": cannot read");
    return parseKeyframes(s.str(), path, defaultUp, defaultFov);
}

CameraKey interpolate(const std::vector<CameraKey>& keys, double t) {
    if (keys.empty()) throw Error("no keyframes");
    if (keys.size() == 1 || t <= keys.front().time) return keys.front();
    if (t >= keys.back().time) return keys.back();
    const size_t n = keys.size();
    std::vector<double> times(n), fov(n);
    std::vector<glm::dvec3> eye(n), look(n), up(n);
    for (size_t k = 0; k < n; ++k) {
        times[k] = keys[k].time;
        fov[k] = keys[k].fovDeg;
        eye[k] = keys[k].eye;
        look[k] = keys[k].lookAt;
        up[k] = glm::normalize(keys[k].up);
    }
    const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const double h = times[k + 1] - times[k], s = (t - times[k]) / h;
    CameraKey c;
    c.time = t;
    c.eye = hermite(eye[k], eye[k + 1], tangent(eye, times, k), tangent(eye, times, k + 1), h, s);
    c.lookAt = hermite(look[k], look[k + 1], tangent(look, times, k), tangent(look, times, k + 1), h, s);
    const glm::dvec3 u = hermite(up[k], up[k + 1], tangent(up, times, k), tangent(up, times, k + 1), h, s);
    c.up = glm::length(u) > 1e-12 ? glm::normalize(u) : up[k];
    const std::vector<double> m = monotoneTangents(fov, times);
    c.fovDeg = hermite(fov[k], fov[k + 1], m[k], m[k + 1], h, s);
    return c;
}

std::vector<double> uniformTimes(const std::vector<CameraKey>& keys, long long frames) {
    checkFrames(frames, "--frames");
    if (keys.empty()) throw Error("no keyframes");
    const double t0 = keys.front().time, t1 = keys.back().time;
    std::vector<double> t(static_cast<size_t>(frames));
    for (long long i = 0; i < frames; ++i) t[size_t(i)] = frames == 1 ? t0 : t0 + (t1 - t0) * double(i) / double(frames - 1);
    return t;
}

std::vector<double> timesAtRate(const std::vector<CameraKey>& keys, double fps) {
    if (!(std::isfinite(fps) && fps > 0.0 && fps <= 1000.0)) throw Error("--fps: must be a number in (0, 1000]");
    if (keys.empty()) throw Error("no keyframes");
    const double t0 = keys.front().time, duration = keys.back().time - t0;
    const double count = std::floor(duration * fps * (1.0 + 1e-12)) + 1.0;
    if (!(count <= double(kMaxFrames)))
        throw Error("--fps: " + std::to_string(duration) + " s at this rate is more than " + std::to_string(kMaxFrames) + " frames");
    std::vector<double> t(static_cast<size_t>(count));
    for (size_t i = 0; i < t.size(); ++i) t[i] = std::min(t0 + double(i) / fps, keys.back().time);
    return t;
}

}  // namespace vdbsplat::animation
