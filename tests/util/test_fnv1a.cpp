// tests/util/test_fnv1a.cpp — util/fnv1a.h: fnv1a64Words, the word-wise fingerprint of in-memory
// arrays (the level-of-detail cache's key): its tail is fnv1a64's, and every single-bit change of
// a table-sized array changes it (the bits a multiply alone would carry only upward included).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "util/fnv1a.h"

namespace vdbsplat {
namespace {

TEST(Fnv1a, WordsHashesATailByteByByte) {
    const unsigned char bytes[7] = {1, 2, 3, 4, 5, 6, 7};
    for (size_t n = 0; n < 8; ++n) EXPECT_EQ(fnv1a64Words(bytes, n), fnv1a64(bytes, n)) << n;
    EXPECT_EQ(fnv1a64Words(bytes, 0, 42u), 42u);
}

TEST(Fnv1a, WordsSeesEveryBitOfALargeArray) {
    std::vector<uint64_t> words(8192);  // 64 KB, a classification table's size
    for (size_t i = 0; i < words.size(); ++i) words[i] = 0x9e3779b97f4a7c15ull * (i + 1);
    const size_t bytes = words.size() * sizeof(uint64_t);
    const uint64_t base = fnv1a64Words(words.data(), bytes);
    EXPECT_EQ(base, fnv1a64Words(words.data(), bytes));  // deterministic
    EXPECT_NE(base, fnv1a64(words.data(), bytes));        // not the byte-wise checksum
    for (const size_t i : {size_t(0), size_t(1), size_t(4095), size_t(8191)})
        for (int bit = 0; bit < 64; ++bit) {
            words[i] ^= uint64_t(1) << bit;
            EXPECT_NE(fnv1a64Words(words.data(), bytes), base) << "word " << i << " bit " << bit;
            words[i] ^= uint64_t(1) << bit;
        }
    // Two words changed together (the last two, by the same bit) change it too.
    words[8190] ^= uint64_t(1) << 63, words[8191] ^= uint64_t(1) << 63;
    EXPECT_NE(fnv1a64Words(words.data(), bytes), base);
}

}  // namespace
}  // namespace vdbsplat
