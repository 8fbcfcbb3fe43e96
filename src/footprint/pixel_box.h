// footprint/pixel_box.h — screen-space bounds shared by every primitive's rasterizer.
// Owns: PixelBox (a continuous axis-aligned box in pixel coordinates, possibly
// unbounded) and its conversion to the integer range of pixels whose CENTRES
// (i + 0.5, j + 0.5) lie inside it, clamped to an image (camera/camera.h).
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

namespace vdbsplat {

/// @brief A continuous box [lo, hi] in pixel coordinates (y down). Components
/// may be ±infinity (a conservative bound that is unbounded on that side).
struct PixelBox {
    glm::dvec2 lo{0.0}, hi{-1.0};  ///< empty by default (hi < lo)
    bool empty() const { return !(hi.x >= lo.x && hi.y >= lo.y); }
};

/// @brief Inclusive integer pixel range [x0, x1] × [y0, y1]; empty when x1 < x0 or y1 < y0.
struct PixelRange {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    bool empty() const { return x1 < x0 || y1 < y0; }
    long long count() const { return empty() ? 0 : (long long)(x1 - x0 + 1) * (y1 - y0 + 1); }
};

/// @brief The pixels of a @p width × @p height image whose centres lie in @p box.
/// Safe for infinite or huge boxes (clamped in double before the integer cast); NaN gives empty.
inline PixelRange pixelRange(const PixelBox& box, int width, int height) {
    if (box.empty()) return {};
    // ceil and floor commute with a clamp to integer bounds; after the clamp the value is finite
    // and small, so they are an integer cast and a compare (std::ceil is a libm call on the
    // x86-64 baseline, and this runs for every primitive).
    auto first = [](double lo, int n) {
        const double x = std::clamp(lo - 0.5, 0.0, (double)n);
        const int i = (int)x;
        return i + (double(i) < x ? 1 : 0);
    };
    auto last = [](double hi, int n) {
        const double x = std::clamp(hi - 0.5, -1.0, (double)n - 1.0);
        const int i = (int)x;
        return i - (double(i) > x ? 1 : 0);
    };
    return {first(box.lo.x, width), first(box.lo.y, height), last(box.hi.x, width), last(box.hi.y, height)};
}

/// @brief The pixels whose centres lie in @p box, not clamped to any image (coordinates
/// are clamped to ±2³⁰ so the integer cast is always defined). For tests and for
/// rasterizers that clip later.
inline PixelRange pixelRange(const PixelBox& box) {
    if (box.empty()) return {};
    constexpr double kLim = 1 << 30;  // captured by value: std::clamp takes references
    auto first = [kLim](double lo) { return (int)std::clamp(std::ceil(lo - 0.5), -kLim, kLim); };
    auto last = [kLim](double hi) { return (int)std::clamp(std::floor(hi - 0.5), -kLim, kLim); };
    return {first(box.lo.x), first(box.lo.y), last(box.hi.x), last(box.hi.y)};
}

}  // namespace vdbsplat
