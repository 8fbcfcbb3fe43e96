// tests/util/test_huge_pages.cpp — the large-buffer allocator (util/huge_pages.h): blocks of
// 2 MiB and more are huge-page aligned and usable to their last byte, small ones come from
// operator new; elements are default-initialised; growDiscarding grows with headroom, never
// shrinks, and does not copy.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "util/huge_pages.h"

namespace vdbsplat {
namespace {

TEST(HugePages, LargeBlocksAreAlignedAndUsableWhole) {
    for (const size_t n : {size_t(1) << 19, (size_t(3) << 20) / sizeof(float) + 7}) {  // exactly 2 MiB; 3 MiB + 28 B
        std::vector<float, HugePageAllocator<float>> v(n, 1.5f);
        EXPECT_EQ(reinterpret_cast<uintptr_t>(v.data()) % huge_pages::kHugePage, 0u) << n;
        std::iota(v.begin(), v.end(), 0.f);
        EXPECT_EQ(v.back(), float(n - 1));
        EXPECT_EQ(v.front(), 0.f);
    }
}

TEST(HugePages, SmallBlocksAndValuesAsGiven) {
    std::vector<double, HugePageAllocator<double>> v(1000, 2.0);  // 8 kB: operator new
    for (double x : v) ASSERT_EQ(x, 2.0);
    v.push_back(3.0);
    EXPECT_EQ(v.back(), 3.0);
}

TEST(HugePages, GrowDiscardingNeverShrinksAndLeavesHeadroom) {
    std::vector<uint32_t, HugePageAllocator<uint32_t>> v;
    growDiscarding(v, 1000);
    EXPECT_GE(v.size(), 1000u);
    EXPECT_LT(v.size(), 2000u);
    const size_t size = v.size();
    growDiscarding(v, 10);  // never shrinks
    EXPECT_EQ(v.size(), size);
    growDiscarding(v, 3u << 20);  // into huge pages
    EXPECT_GE(v.size(), 3u << 20);
    v[v.size() - 1] = 7;
    EXPECT_EQ(v.back(), 7u);
}

}  // namespace
}  // namespace vdbsplat
