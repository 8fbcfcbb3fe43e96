// tests/util/test_huge_pages.cpp — the large-buffer allocator (util/huge_pages.h): blocks of
// 2 MiB and more are huge-page aligned and usable to their last byte, small ones come from
// operator new; elements are default-initialised; growDiscarding grows to 4n of address space
// (not resident until written), never shrinks, and does not copy; only the huge pages a caller
// fills at least half of are advised for huge pages (adviseWritten).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "image/image.h"
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
    EXPECT_EQ(v.size(), 4000u);  // 4n: later, larger windows reuse the same block
    const size_t size = v.size();
    growDiscarding(v, 10);  // never shrinks
    EXPECT_EQ(v.size(), size);
    growDiscarding(v, 4000);  // fits: the same block
    EXPECT_EQ(v.size(), size);
    growDiscarding(v, 3u << 20);  // into huge pages
    EXPECT_GE(v.size(), 3u << 20);
    v[0] = 5;
    v[v.size() - 1] = 7;
    EXPECT_EQ(v.front(), 5u);
    EXPECT_EQ(v.back(), 7u);
}

// The headroom is address space: pages nobody wrote are not resident (growDiscarding constructs
// nothing), so the window buffers' memory is what the largest window wrote.
TEST(HugePages, GrowDiscardingHeadroomIsNotResident) {
    std::vector<uint32_t, HugePageAllocator<uint32_t>> v;
    growDiscarding(v, 4u << 20);  // 16 MB asked, 64 MB mapped
    ASSERT_EQ(v.size(), 16u << 20);
    for (size_t i = 0; i < (4u << 20); ++i) v[i] = uint32_t(i);
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    const auto resident = [&](size_t element) {
        auto* at = reinterpret_cast<unsigned char*>(v.data() + element);
        auto* start = reinterpret_cast<unsigned char*>(reinterpret_cast<uintptr_t>(at) / page * page);
        unsigned char in = 0;
        EXPECT_EQ(mincore(start, page, &in), 0);
        return (in & 1) != 0;
    };
    EXPECT_TRUE(resident(0));
    EXPECT_TRUE(resident((4u << 20) - 1));
    EXPECT_FALSE(resident(v.size() - 1));       // 48 MB past what was written
    EXPECT_FALSE(resident(v.size() / 2 + 17));  // 16 MB past it
}

/// Whether the mapping holding @p address is advised for huge pages ("hg" in its VmFlags in
/// /proc/self/smaps); nullopt where smaps cannot be read.
std::optional<bool> advisedHuge(const void* address) {
    std::ifstream smaps("/proc/self/smaps");
    if (!smaps) return std::nullopt;
    const auto at = reinterpret_cast<uintptr_t>(address);
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(' ') != std::string::npos &&
            line.find(':') > line.find(' ')) {
            inside = lo <= at && at < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line.find(" hg") != std::string::npos;
    }
    return std::nullopt;
}

/// Whether this kernel takes madvise(MADV_HUGEPAGE) (it fails without transparent huge pages).
bool hugePagesAdvisable() {
    void* probe = huge_pages::map(huge_pages::kHugePage);
    const bool supported = madvise(probe, huge_pages::kHugePage, MADV_HUGEPAGE) == 0;
    munmap(probe, huge_pages::kHugePage);
    return supported;
}

// A window that writes a little of a large block takes ordinary pages: a huge page is cleared whole
// at its first touch. The huge pages the written part fills at least half of are advised.
TEST(HugePages, OnlyTheWrittenHugePagesAreAdvised) {
    if (!hugePagesAdvisable()) GTEST_SKIP() << "madvise(MADV_HUGEPAGE) is not supported here";
    std::vector<uint32_t, HugePageAllocator<uint32_t>> v;
    growDiscarding(v, 200'000);  // 800 kB to write, 3.2 MB mapped: less than half a huge page
    ASSERT_EQ(reinterpret_cast<uintptr_t>(v.data()) % huge_pages::kHugePage, 0u);
    const std::optional<bool> before = advisedHuge(v.data());
    if (!before) GTEST_SKIP() << "/proc/self/smaps cannot be read";
    EXPECT_FALSE(*before);
    growDiscarding(v, 300'000);  // 1.2 MB: more than half of the first huge page, none of the second
    EXPECT_EQ(advisedHuge(v.data()), std::optional<bool>(true));
    EXPECT_EQ(advisedHuge(v.data() + huge_pages::kHugePage / sizeof(uint32_t)), std::optional<bool>(false));
}

// The window's pending voxels grow past their room keeping what they hold; the new block is advised
// before the copy, so the copy itself takes huge pages.
TEST(HugePages, ResizeWrittenKeepsTheContentsAndAdvisesTheNewBlock) {
    std::vector<uint32_t, HugePageAllocator<uint32_t>> v;
    resizeWritten(v, 1000);
    std::iota(v.begin(), v.end(), 7u);
    resizeWritten(v, size_t(2) << 20);  // 8 MB: past the capacity, into a mapped block
    ASSERT_EQ(v.size(), size_t(2) << 20);
    for (uint32_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], 7u + i);
    if (const std::optional<bool> advised = advisedHuge(v.data() + (size_t(1) << 20)); advised && hugePagesAdvisable()) {
        EXPECT_TRUE(*advised);
    }
    resizeWritten(v, 10);  // shrinks the size, keeps the block
    EXPECT_EQ(v.size(), 10u);
    EXPECT_EQ(v[9], 16u);
    EXPECT_GE(v.capacity(), size_t(2) << 20);
}

// A far view's crop writes a few hundred pixels of each of its rows: those rows stay in small
// pages. A crop as wide as the image (a framed view) takes huge pages for its rows.
TEST(HugePages, AnImageIsAdvisedWhereItsRowsAreMostlyWritten) {
    if (!hugePagesAdvisable()) GTEST_SKIP() << "madvise(MADV_HUGEPAGE) is not supported here";
    Image narrow(1024, 1024);  // 16 MB, mapped: a row is 16 kB, a huge page 128 rows
    ASSERT_EQ(reinterpret_cast<uintptr_t>(narrow.pixels.data()) % huge_pages::kHugePage, 0u);
    adviseRowsWritten(narrow, 300, 400, 300);  // 300 of 1024 columns
    const std::optional<bool> before = advisedHuge(&narrow.at(0, 400));
    if (!before) GTEST_SKIP() << "/proc/self/smaps cannot be read";
    EXPECT_FALSE(*before);
    Image wide(1024, 1024);
    adviseRowsWritten(wide, 300, 400, 1000);  // rows 300 … 699: huge pages 2 … 5 (rows 256 … 767)
    EXPECT_EQ(advisedHuge(&wide.at(0, 400)), std::optional<bool>(true));
    EXPECT_EQ(advisedHuge(&wide.at(0, 300)), std::optional<bool>(true));
    EXPECT_EQ(advisedHuge(&wide.at(0, 100)), std::optional<bool>(false));  // huge page 0: not written
    EXPECT_EQ(advisedHuge(&wide.at(0, 900)), std::optional<bool>(false));
    Image edge(1024, 1024);
    adviseRowsWritten(edge, 120, 200, 1024);  // rows 120 … 319: 8 of huge page 0's 128 rows, all of 1's, 64 of 2's
    EXPECT_EQ(advisedHuge(&edge.at(0, 50)), std::optional<bool>(false));  // an end page written less than half
    EXPECT_EQ(advisedHuge(&edge.at(0, 200)), std::optional<bool>(true));
    EXPECT_EQ(advisedHuge(&edge.at(0, 300)), std::optional<bool>(true));  // exactly half
}

}  // namespace
}  // namespace vdbsplat
