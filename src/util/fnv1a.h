// util/fnv1a.h — FNV-1a 64, the fingerprint the project uses (table checksums, study and
// animation folders' camera and settings fingerprints), and its word-wise form for large arrays in
// memory (fnv1a64Words: cache keys). Not cryptographic: they tell a changed input from an
// unchanged one, nothing more.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

namespace vdbsplat {

inline constexpr std::uint64_t kFnv1aOffsetBasis = 14695981039346656037ull;  // 0xcbf29ce484222325
inline constexpr std::uint64_t kFnv1aPrime = 1099511628211ull;               // 0x100000001b3

/// @brief FNV-1a 64 of @p size bytes at @p data, continuing from @p h (the offset basis: a new hash).
inline std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t h = kFnv1aOffsetBasis) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * kFnv1aPrime;
    return h;
}

/// @brief FNV-1a's step a 64-bit word at a time (the word's bytes as loaded, little-endian here),
/// with a fold of the high half into the low after each multiply (the multiply carries a word's
/// bits only upward): for in-memory fingerprints of large arrays, 8× fewer steps than fnv1a64 (the
/// level-of-detail cache's key over a 64 KB classification table took ~60 µs of every render,
/// 2 % of a warm far view; docs/performance.md, session 47). Not a file format's checksum: its
/// value is not fnv1a64's. A tail of @p size mod 8 bytes is hashed byte by byte.
inline std::uint64_t fnv1a64Words(const void* data, std::size_t size, std::uint64_t h = kFnv1aOffsetBasis) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= size; i += 8) {
        std::uint64_t w;
        std::memcpy(&w, p + i, 8);
        h = (h ^ w) * kFnv1aPrime;
        h ^= h >> 32;
    }
    return fnv1a64(p + i, size - i, h);
}

/// @brief FNV-1a 64 of @p text as 16 lower-case hex digits.
inline std::string fnv1aHex(std::string_view text, std::uint64_t basis = kFnv1aOffsetBasis) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)fnv1a64(text.data(), text.size(), basis));
    return buf;
}

}  // namespace vdbsplat
