// study/views.h — the views an antialiasing study renders, and the names its files get.
// Owns: the standard three views (framing distance 8 far, 1 framed, 0.35 close), the
// Mip-Splatting-style zoom ladder (zoom 1/8×, 1/4×, 1/2×, 1×, 2×, 4×, 8× around a base view:
// zoom s puts the eye at framing distance base / s, so the volume looks s times larger on
// screen), the parsing of comma-separated study lists, file-safe ids, and the FNV-1a
// fingerprint that marks which settings a finished render was made with.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace vdbsplat::study {

/// One camera of the study: the framing distance render's --distance takes.
struct View {
    std::string id;      ///< file-safe, unique within a study: "d8", "d0_35"
    std::string label;   ///< for people: "far (distance 8)", "zoom 1/8x (distance 8)"
    double distance = 1.0;
    /// Magnification against the framed view (1 / distance): the x axis of the study's plots.
    double zoom() const { return 1.0 / distance; }
};

/// The nearest framing distance a study takes: far inside any grid's bounds (1e-4 of the framing
/// distance), well before the eye and the look-at point coincide in double precision.
inline constexpr double kMinDistance = 1e-4;

/// Most views one study accepts (each is rendered in every mode, kernel and volume).
inline constexpr size_t kMaxViews = 64;

/// @brief far (8), framed (1), close (0.35): the views of the fidelity table and `bench`.
std::vector<View> standardViews();

/// @brief Zoom 1/8× … 8× in factors of two around framing distance @p base (distance base/s).
/// @throw Error "--base: …" unless 0.001 <= base < 1e5 (so every distance is at least kMinDistance).
std::vector<View> zoomLadder(double base);

/// @brief A view at framing distance @p distance, labelled with it ("distance 2.5").
View viewAt(double distance);

/// @brief @p views without the later repeats of a distance (the first label is kept), in order.
std::vector<View> withoutRepeats(const std::vector<View>& views);

/// @brief "d" + the distance in %g with '.' as '_' and '-' as 'm' ("d0_35", "d1e+06" → "d1ep06").
std::string viewId(double distance);


/// @brief A file-safe id from @p text: letters, digits, '-' and '_' kept, anything else '_',
/// at most 48 characters; "volume" when nothing is left.
std::string safeId(const std::string& text);

/// @brief FNV-1a 64 of @p text as 16 hex digits.
std::string fnv1a(const std::string& text);

}  // namespace vdbsplat::study
