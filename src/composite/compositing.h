// composite/compositing.h — the compositor's two orders of compositing (`--compositing`).
// Owns: CompositingOrder and SlabCompositing, what the projection and the compositor agree on.
//   Kernels — DESIGN §4 as first built: each splat composited whole ("over") at its centre's
//             depth, the points of one slab summed and composited when the slab ends;
//   Slabs   — every primitive deposits its optical depth and σ-weighted colour into the radial
//             slabs its kernel spans, by the fractions of its profile along the ray
//             (composite/slab_profile.h), and each slab is composited once per pixel when the
//             stream has passed every primitive that reaches it (docs/compositing.md).
#pragma once

namespace vdbsplat {

enum class CompositingOrder { Kernels, Slabs };

/// @brief What the projection and the compositor share in the Slabs order.
struct SlabCompositing {
    bool on = false;
    int reach = 0;  ///< K: a primitive of slab s deposits into slabs s − K … s + K (≤ kMaxSlabReach)
};

}  // namespace vdbsplat
