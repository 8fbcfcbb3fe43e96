// util/huge_pages.h — an allocator for the renderer's large per-window buffers.
// Owns: HugePageAllocator, a standard allocator that maps blocks of 2 MiB and more as
// anonymous memory aligned for transparent huge pages, and smaller blocks through operator new;
// huge_pages::map, which the output image's large blocks use too (image/image.h: fresh zero
// pages for every frame); adviseWritten, which asks for huge pages (madvise MADV_HUGEPAGE) only
// over the part of a block a caller is about to write, and growDiscarding, which does so.
//
// Why: the first touch of a fresh 4 KiB page costs a fault, and on the virtual machines this
// project is measured on a fault costs 20–30 µs (docs/performance.md, "Loading"): touching 64 MiB
// of fresh malloc memory took 0.35–0.44 s there, the same memory in huge pages 0.006–0.2 s. The
// projected window, its sort order, the gathered tile records and the frame are tens of MiB, grown
// window after window; in 2 MiB pages they fault 512× less often. But a huge page is cleared (and
// backed) whole at its first touch, so only the huge pages a caller fills at least half of are
// advised (session 30). Where the kernel gives no huge pages (THP off, or none free), the memory
// is ordinary pages: correct, only not faster.
#pragma once
#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>

namespace vdbsplat {

namespace huge_pages {
inline constexpr std::size_t kHugePage = std::size_t(2) << 20;  ///< x86-64 and AArch64 (4 KiB granule)

inline std::size_t roundUp(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

/// @brief Maps @p bytes (a multiple of kHugePage), aligned to kHugePage, advised for huge pages.
/// @throw std::bad_alloc when the mapping fails.
inline void* map(std::size_t bytes) {
    // Over-map by one huge page and trim, so the block starts on a huge-page boundary.
    void* raw = mmap(nullptr, bytes + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const std::size_t start = reinterpret_cast<std::size_t>(raw);
    const std::size_t aligned = (start + kHugePage - 1) / kHugePage * kHugePage;
    if (aligned > start) munmap(raw, aligned - start);
    if (const std::size_t tail = start + bytes + kHugePage - (aligned + bytes); tail > 0)
        munmap(reinterpret_cast<void*>(aligned + bytes), tail);
    return reinterpret_cast<void*>(aligned);
}
/// @brief Advises huge pages for the huge pages of a block from map() (which starts on a
/// huge-page boundary) that the bytes [@p from, @p to) of it, the part a caller is about to write,
/// fill at least half of. Memory is mapped unadvised: a huge page costs its whole 2 MiB at the first
/// touch (cleared by the kernel, and on a paravirtualised host backed by the host too: 1.3–6 ms cold
/// on the hosts measured), and a window that writes 100 KiB of a buffer reserved for 2^18 records
/// paid that for each of its arrays; a 4 KiB page costs 2–11 µs there (docs/performance.md,
/// sessions 29, 30). Only the two end pages can be partly written.
inline void adviseWritten(void* block, std::size_t from, std::size_t to) {
    if (to <= from) return;
    std::size_t first = from / kHugePage, last = (to - 1) / kHugePage;
    if (std::min(to, (first + 1) * kHugePage) - from < kHugePage / 2) ++first;
    if (last >= first && to - std::max(from, last * kHugePage) < kHugePage / 2) --last;
    if (last + 1 > first)  // advice only: failure leaves ordinary pages
        madvise(static_cast<char*>(block) + first * kHugePage, (last + 1 - first) * kHugePage, MADV_HUGEPAGE);
}
}  // namespace huge_pages

/// @brief std::allocator's interface; blocks of at least 2 MiB come from huge_pages::map, and
/// elements are default-initialised, not value-initialised (see construct()).
template <class T>
struct HugePageAllocator {
    using value_type = T;
    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T);
        if (bytes < huge_pages::kHugePage) return static_cast<T*>(::operator new(bytes, std::align_val_t(alignof(T) > 16 ? alignof(T) : 16)));
        return static_cast<T*>(huge_pages::map(huge_pages::roundUp(bytes)));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        const std::size_t bytes = n * sizeof(T);
        if (bytes < huge_pages::kHugePage) ::operator delete(p, std::align_val_t(alignof(T) > 16 ? alignof(T) : 16));
        else munmap(p, huge_pages::roundUp(bytes));
    }
    /// Default construction leaves trivially copyable, trivially destructible elements as they
    /// are, even where the type has default member initialisers (Primitive, ExactIndexMap): such
    /// a type is an implicit-lifetime type (C++20, P0593), so the mapped memory already holds its
    /// objects, and the renderer's window buffers are written before they are read. Otherwise
    /// vector::resize would write every element (and take every page fault) serially on the
    /// calling thread; now the first writes, in the parallel passes, fault the pages in.
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        if constexpr (!(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>))
            ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <class U>
    bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

/// @brief huge_pages::adviseWritten for the first @p n elements of @p buffer, if its block came
/// from huge_pages::map (2 MiB and more).
template <class Buffer>
void adviseWritten(Buffer& buffer, std::size_t n) {
    constexpr std::size_t kSize = sizeof(typename Buffer::value_type);
    if (buffer.capacity() * kSize >= huge_pages::kHugePage) huge_pages::adviseWritten(buffer.data(), 0, std::min(n, buffer.capacity()) * kSize);
}

/// @brief Resizes @p buffer to @p n elements, keeping its contents, with its first n advised
/// (adviseWritten: the caller writes what is new). Growth past the capacity takes a block of at
/// least twice it, advised before the old elements are copied in: std::vector's own growth would
/// copy them into unadvised pages first.
template <class Buffer>
void resizeWritten(Buffer& buffer, std::size_t n) {
    if (n > buffer.capacity()) {
        Buffer bigger;
        bigger.reserve(std::max(n, 2 * buffer.capacity()));
        adviseWritten(bigger, n);
        bigger.assign(buffer.begin(), buffer.end());
        buffer.swap(bigger);
    } else {
        adviseWritten(buffer, n);
    }
    buffer.resize(n);
}

/// @brief Grows @p buffer to at least @p n elements without keeping its contents (a window's
/// buffers are rewritten whole): no copy on growth. Never shrinks. The first n are advised for
/// huge pages (adviseWritten): the caller writes them.
///
/// It grows to 4n: address space, not memory. The allocator constructs nothing (construct()
/// above), so only the pages a window writes are faulted in, and a later window up to 4n reuses
/// the pages the earlier ones faulted instead of faulting a fresh, larger block in again. Growing
/// by exactly what was asked (or 1/8 more) re-faulted the whole prefix at every larger window: on
/// the framed Engine at 400² the window buffers grew six times and faulted in 118 MB of huge
/// pages for 26 MB of final buffers (docs/performance.md). What is resident stays bounded by the
/// largest window (DESIGN §5).
template <class Buffer>
void growDiscarding(Buffer& buffer, std::size_t n) {
    if (buffer.size() < n) {
        Buffer().swap(buffer);
        buffer.resize(n > buffer.max_size() / 4 ? n : 4 * n);
    }
    adviseWritten(buffer, n);
}
}  // namespace vdbsplat
