// tests/volume/test_leaf_values.cpp — sanitizeLeafValues (volume/leaf_values.h) on every SIMD
// target against the bit-by-bit oracle: the same values zeroed, the same bits cleared, the same
// count, and the same range (equal as numbers; a 0 extreme's sign is the caller's to settle) on
// leaves dense, sparse, empty and single, with NaN, ±∞, ±0, subnormals and the float extremes.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "support/targets.h"
#include "volume/leaf_values.h"

namespace vdbsplat {
namespace {

struct Leaf {
    float values[512];
    uint64_t mask[8];
};

float specialOrRandom(std::mt19937& rng) {
    constexpr float kSpecial[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity(), 0.0f, -0.0f,
                                  std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max(),
                                  std::numeric_limits<float>::lowest(), 1.0f};
    std::uniform_real_distribution<float> u(-4.f, 4.f);
    if (rng() % 16 == 0) return kSpecial[rng() % std::size(kSpecial)];
    return u(rng);
}

Leaf randomLeaf(std::mt19937& rng, int trial) {
    Leaf l;
    for (float& v : l.values) v = specialOrRandom(rng);
    const int kind = trial % 5;  // dense, sparse, empty, one value, random words
    for (int w = 0; w < 8; ++w) {
        const uint64_t r = (uint64_t(rng()) << 32) | rng();
        l.mask[w] = kind == 0 ? ~uint64_t(0) : kind == 1 ? r & (uint64_t(rng()) << 32 | rng()) : kind == 2 ? 0 : kind == 3 ? 0 : r;
    }
    if (kind == 3) l.mask[rng() % 8] = uint64_t(1) << (rng() % 64);
    if (kind == 4) l.mask[rng() % 8] = ~uint64_t(0);
    return l;
}

void matchesTheScalarPass() {
    std::mt19937 rng(19);
    int nonFinite = 0, ranged = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        Leaf a = randomLeaf(rng, trial), b = a;
        float loA, hiA, loB, hiB;
        const uint64_t countA = sanitizeLeafValues(a.values, a.mask, loA, hiA);
        const uint64_t countB = sanitizeLeafValuesScalar(b.values, b.mask, loB, hiB);
        ASSERT_EQ(countA, countB) << "trial " << trial;
        ASSERT_EQ(std::memcmp(a.mask, b.mask, sizeof a.mask), 0) << "trial " << trial;
        ASSERT_EQ(std::memcmp(a.values, b.values, sizeof a.values), 0) << "trial " << trial;  // NaN bits too
        ASSERT_EQ(loA, loB) << "trial " << trial;  // as numbers: +0 == −0
        ASSERT_EQ(hiA, hiB) << "trial " << trial;
        if (loB != 0.0f) {
            ASSERT_EQ(std::bit_cast<uint32_t>(loA), std::bit_cast<uint32_t>(loB)) << "trial " << trial;
        }
        if (hiB != 0.0f) {
            ASSERT_EQ(std::bit_cast<uint32_t>(hiA), std::bit_cast<uint32_t>(hiB)) << "trial " << trial;
        }
        nonFinite += countB > 0;
        ranged += loB <= hiB;
    }
    EXPECT_GT(nonFinite, 500);  // the trials did meet non-finite values
    EXPECT_GT(ranged, 1000);    // and measured ranges
}

TEST(LeafValues, SanitizeMatchesTheScalarPass) { test::forEachTarget([] { matchesTheScalarPass(); }); }

TEST(LeafValues, AnEmptyLeafHasNoRange) {
    Leaf l{};
    float lo, hi;
    EXPECT_EQ(sanitizeLeafValues(l.values, l.mask, lo, hi), 0u);
    EXPECT_GT(lo, hi);
}

TEST(LeafValues, EveryNonFiniteActiveValueIsZeroedAndUnmarked) {
    Leaf l{};
    for (float& v : l.values) v = 2.f;
    for (uint64_t& w : l.mask) w = ~uint64_t(0);
    l.values[0] = std::numeric_limits<float>::quiet_NaN();
    l.values[100] = -std::numeric_limits<float>::infinity();
    l.values[511] = std::numeric_limits<float>::infinity();
    l.values[300] = -1.f, l.values[301] = 7.f;
    l.mask[4] &= ~(uint64_t(1) << (301 - 256));  // 7 is inactive: not in the range
    l.values[200] = std::numeric_limits<float>::quiet_NaN();
    l.mask[3] &= ~(uint64_t(1) << (200 - 192));  // an inactive NaN stays as it is
    float lo, hi;
    EXPECT_EQ(sanitizeLeafValues(l.values, l.mask, lo, hi), 3u);
    EXPECT_EQ(l.values[0], 0.f);
    EXPECT_EQ(l.values[100], 0.f);
    EXPECT_EQ(l.values[511], 0.f);
    EXPECT_TRUE(std::isnan(l.values[200]));
    EXPECT_EQ(l.mask[0] & 1, 0u);
    EXPECT_EQ(l.mask[1] >> (100 - 64) & 1, 0u);
    EXPECT_EQ(l.mask[7] >> 63, 0u);
    EXPECT_EQ(lo, -1.f);
    EXPECT_EQ(hi, 2.f);
}

}  // namespace
}  // namespace vdbsplat
