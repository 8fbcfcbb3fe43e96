// util/radix_sort.h — the one radix sort of 64-bit keys (the compositor's tile lists, the
// stream's block order).
// Owns: radixSortBits, a stable least-significant-digit sort on a field of bits, 8 a pass.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace vdbsplat {

/// Sorts the @p n words at @p a by their bits [@p low, @p low + @p bits), stably (words with the
/// same field keep their order), 8 bits a pass; a pass whose digit is the same in every word
/// moves nothing and is skipped. @p scratch has room for n words. Returns where the result is
/// (@p a or @p scratch). With low = 0 and bits = 64, distinct words end in value order.
inline uint64_t* radixSortBits(uint64_t* a, uint64_t* scratch, size_t n, int low, int bits) {
    uint64_t *from = a, *to = scratch;
    if (n == 0) return from;
    // Every pass's digit counts in one read of the words (a permutation keeps them): the passes
    // then only scatter. Counted pass by pass, a short list (a tile's few hundred entries) was
    // read once more per pass.
    constexpr int kMaxPasses = 8;
    const int passes = std::min((bits + 7) / 8, kMaxPasses);
    std::array<std::array<uint32_t, 256>, kMaxPasses> start;
    for (int p = 0; p < (passes <= 4 ? passes : kMaxPasses); ++p) start[size_t(p)].fill(0);  // the rows count() fills
    const auto count = [&]<int P>(std::integral_constant<int, P>) {  // the passes unrolled
        for (size_t i = 0; i < n; ++i) {
            const uint64_t w = from[i] >> low;
            for (int p = 0; p < P; ++p) ++start[size_t(p)][(w >> (8 * p)) & 0xff];
        }
    };
    switch (passes) {
        case 1: count(std::integral_constant<int, 1>()); break;
        case 2: count(std::integral_constant<int, 2>()); break;
        case 3: count(std::integral_constant<int, 3>()); break;
        case 4: count(std::integral_constant<int, 4>()); break;
        default: count(std::integral_constant<int, kMaxPasses>()); break;
    }
    for (int p = 0; p < passes; ++p) {
        const int shift = low + 8 * p;
        std::array<uint32_t, 256>& at = start[size_t(p)];
        if (at[(from[0] >> shift) & 0xff] == n) continue;  // one digit: the pass would copy
        uint32_t total = 0;
        for (uint32_t& c : at) total += std::exchange(c, total);
        for (size_t i = 0; i < n; ++i) to[at[(from[i] >> shift) & 0xff]++] = from[i];
        std::swap(from, to);
    }
    return from;
}

}  // namespace vdbsplat
