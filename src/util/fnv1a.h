// util/fnv1a.h — FNV-1a 64, the one fingerprint the project uses (table checksums, study and
// animation folders' camera and settings fingerprints). Not cryptographic: it tells a changed
// input from an unchanged one, nothing more.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
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

/// @brief FNV-1a 64 of @p text as 16 lower-case hex digits.
inline std::string fnv1aHex(std::string_view text, std::uint64_t basis = kFnv1aOffsetBasis) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)fnv1a64(text.data(), text.size(), basis));
    return buf;
}

}  // namespace vdbsplat
