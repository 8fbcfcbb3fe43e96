// tests/composite/test_tile_sort.cpp — a tile's list sorted against std::stable_sort by key.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <vector>

#include "composite/tile_sort.h"

namespace vdbsplat {
namespace {

/// Entries as the binning makes them: key << indexBits | index, in index order, keys drawn from
/// @p distinctKeys values of @p keyBits bits (few values: many ties), every digit of @p fixedBits
/// low key bits the same (the radix skips those passes).
std::vector<uint64_t> binnedEntries(size_t n, int indexBits, int keyBits, uint64_t distinctKeys, int fixedBits,
                                    std::mt19937_64& rng) {
    std::vector<uint64_t> pool(distinctKeys);
    const uint64_t keyMask = keyBits >= 64 ? ~uint64_t(0) : (uint64_t(1) << keyBits) - 1;
    for (uint64_t& k : pool) k = (rng() & keyMask) >> fixedBits << fixedBits | (uint64_t(0x5a) & ((uint64_t(1) << fixedBits) - 1));
    std::vector<uint64_t> entries;
    uint64_t index = rng() % 4;  // a tile's list skips indices: any increasing run will do
    for (size_t i = 0; i < n; ++i, index += 1 + rng() % 3) entries.push_back(pool[rng() % pool.size()] << indexBits | index);
    EXPECT_LT(index, uint64_t(1) << indexBits) << "the test's indices overflow their bits";
    return entries;
}

/// What the tile must see: the (key, index) order, i.e. a stable sort by key of the index order.
std::vector<uint64_t> byKeyThenIndex(std::vector<uint64_t> entries, int indexBits) {
    std::stable_sort(entries.begin(), entries.end(), [&](uint64_t a, uint64_t b) { return a >> indexBits < b >> indexBits; });
    return entries;
}

TEST(TileSort, EqualsTheStableSortByKey) {
    std::mt19937_64 rng(15);
    struct Case { size_t n; int keyBits; uint64_t distinct; int fixedBits; };
    const Case cases[] = {
        {0, 8, 1, 0},                  // empty
        {1, 20, 5, 0},
        {kTileRadixFrom - 1, 23, 40, 0},   // the comparison sort's largest list
        {kTileRadixFrom, 23, 40, 0},       // the radix sort's smallest
        {kTileRadixFrom + 1, 23, 3, 0},    // few keys: long runs of ties
        {5000, 23, 5000, 0},
        {5000, 23, 7, 8},              // the lowest digit the same everywhere: a skipped pass
        {5000, 44, 5000, 16},              // 44 bits: 6 passes, 2 skipped
        {3000, 42, 1, 0},              // one key: every pass skipped, the index order stands
        {3001, 30, 2, 0},              // two keys: a digit most entries share is still a pass
        {kTileRadixFrom + 2, 16, 2, 0},
        {4097, 50, 200, 3},                // key and index fill 64 bits
    };
    for (const Case& c : cases) {
        const int indexBits = int(std::bit_width(3 * c.n + 4));  // room for binnedEntries' indices
        ASSERT_LE(indexBits + c.keyBits, 64);
        const std::vector<uint64_t> binned = binnedEntries(c.n, indexBits, c.keyBits, c.distinct, c.fixedBits, rng);
        std::vector<uint64_t> a = binned, scratch(c.n);
        const uint64_t* sorted = sortTileEntries(a.data(), scratch.data(), c.n, indexBits, c.keyBits);
        const std::vector<uint64_t> got(sorted, sorted + c.n);
        EXPECT_EQ(got, byKeyThenIndex(binned, indexBits)) << "n " << c.n << ", key bits " << c.keyBits;
    }
}

}  // namespace
}  // namespace vdbsplat
