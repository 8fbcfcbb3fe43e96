// composite/tile_sort.h — ordering one screen tile's list of primitives (compositor.h).
// Owns: sortTileEntries, the sort each tile runs on its own list just before compositing it.
// An entry is one 64-bit word, a key (slab, kind, depth; the compositor's KeyLayout) above the
// primitive's index in its window; the lists arrive in index order from the binning.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "util/radix_sort.h"

namespace vdbsplat {

/// Below this many entries a tile's list is sorted by comparison; from it on by radix.
inline constexpr size_t kTileRadixFrom = 256;

/// Sorts one tile's @p n entries at @p a (key << low | index, each key @p bits wide, in index
/// order as binned) into (key, index) order; returns where the result is (@p a or @p scratch, n
/// entries of room). The entries are distinct (their indices are), so the order of their values
/// is the (key, index) order: a short list takes std::sort; a long one a stable radix sort of the
/// key's bits (util/radix_sort.h), which keeps the index order among equal keys. The list is one
/// tile's (a few KiB to a few hundred), so its passes run in the cache of the thread that
/// composites the tile next.
inline uint64_t* sortTileEntries(uint64_t* a, uint64_t* scratch, size_t n, int low, int bits) {
    if (n < kTileRadixFrom) {
        std::sort(a, a + n);
        return a;
    }
    return radixSortBits(a, scratch, n, low, bits);
}

}  // namespace vdbsplat
