// util/radix_sort.h — the one radix sort of 64-bit keys (the compositor's tile lists, the
// stream's block order).
// Owns: radixSortBits, a stable least-significant-digit sort on a field of bits, 8 a pass.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace vdbsplat {

/// Sorts the @p n words at @p a by their bits [@p low, @p low + @p bits), stably (words with the
/// same field keep their order), 8 bits a pass; a pass whose digit is the same in every word
/// moves nothing and is skipped. @p scratch has room for n words. Returns where the result is
/// (@p a or @p scratch). With low = 0 and bits = 64, distinct words end in value order.
inline uint64_t* radixSortBits(uint64_t* a, uint64_t* scratch, size_t n, int low, int bits) {
    uint64_t *from = a, *to = scratch;
    if (n == 0) return from;
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
