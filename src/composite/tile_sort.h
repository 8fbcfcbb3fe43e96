// composite/tile_sort.h — ordering one screen tile's list of primitives (compositor.h).
// Owns: sortTileEntries, the sort each tile runs on its own list just before compositing it.
// An entry is one 64-bit word, a key (slab, kind, depth; the compositor's KeyLayout) above the
// primitive's index in its window; the lists arrive in index order from the binning.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace vdbsplat {

/// Below this many entries a tile's list is sorted by comparison; from it on by radix.
inline constexpr size_t kTileRadixFrom = 256;

/// Sorts one tile's @p n entries at @p a (key << low | index, each key @p bits wide, in index
/// order as binned) into (key, index) order; returns where the result is (@p a or @p scratch, n
/// entries of room). The entries are distinct (their indices are), so the order of their values
/// is the (key, index) order: a short list takes std::sort; a long one a stable LSD radix sort of
/// the key's bits, 8 a pass, which keeps the index order among equal keys. A pass whose digit is
/// the same in every entry moves nothing and is skipped. The list is one tile's (a few KiB to a
/// few hundred), so its passes run in the cache of the thread that composites the tile next.
inline uint64_t* sortTileEntries(uint64_t* a, uint64_t* scratch, size_t n, int low, int bits) {
    if (n < kTileRadixFrom) {
        std::sort(a, a + n);
        return a;
    }
    uint64_t *from = a, *to = scratch;
    std::array<uint32_t, 256> start;
    for (int shift = low; shift < low + bits; shift += 8) {
        start.fill(0);
        for (size_t i = 0; i < n; ++i) ++start[(from[i] >> shift) & 0xff];
        if (start[(from[0] >> shift) & 0xff] == n) continue;  // one digit: the pass would copy
        uint32_t total = 0;
        for (uint32_t& c : start) total += std::exchange(c, total);
        for (size_t i = 0; i < n; ++i) to[start[(from[i] >> shift) & 0xff]++] = from[i];
        std::swap(from, to);
    }
    return from;
}

}  // namespace vdbsplat
