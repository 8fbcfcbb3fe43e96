// composite/compositing.h — the compositor's two orders of compositing (`--compositing`), and
// its colour channels.
// Owns: CompositingOrder, SlabCompositing and ColorChannels, what the renderer and the compositor
// agree on.
//   Kernels — DESIGN §4 as first built: each splat composited whole ("over") at its centre's
//             depth, the points of one slab summed and composited when the slab ends;
//   Slabs   — every primitive deposits its optical depth and σ-weighted colour into the radial
//             slabs its kernel spans, by the fractions of its profile along the ray
//             (composite/slab_profile.h), and each slab is composited once per pixel when the
//             stream has passed every primitive that reaches it (docs/compositing.md).
#pragma once

namespace vdbsplat {

/// @brief The transmittance below which a pixel is finished (early termination), unless a render
/// sets another (RenderSettings::cutoff, --cutoff). The deposit that finishes a pixel takes its
/// whole remainder (T·c, docs/compositing.md), so a cutoff ten times the reference's 1e-4
/// (render/reference.h) scores against it within 0.01 dB of what 1e-4 without the remainder did,
/// or better, on every cell of docs/fidelity.md's table (docs/fidelity.md, session 40).
inline constexpr double kDefaultCutoff = 1e-3;

enum class CompositingOrder { Kernels, Slabs };

/// @brief The colour channels the compositor's vector loops carry. Grey: every primitive's colour
/// is grey (c.x = c.y = c.z: a grey transfer function, shaded by white light or not, no emission),
/// so compositing green and blue would repeat red's operations on red's values; the loops
/// composite T and R (or deposit τ and the red sums, in the slab order) alone and the frame's G
/// and B are R. The image is the Rgb one bit for bit, for half the loads and stores of each deposit.
enum class ColorChannels { Rgb, Grey };

/// @brief What the projection and the compositor share in the Slabs order.
struct SlabCompositing {
    bool on = false;
    int reach = 0;  ///< K: a primitive of slab s deposits into slabs s − K … s + K (≤ kMaxSlabReach)
};

}  // namespace vdbsplat
