// scripts/fault-cost.cpp — what fresh memory costs on this host: first touches of 4 KiB pages (one
// thread, then two), of transparent huge pages (madvise MADV_HUGEPAGE), and the same 4 KiB pages
// faulted in by one madvise(MADV_POPULATE_WRITE) call. Run it twice a few seconds apart: huge pages
// the previous process freed a moment ago are cheap, ones the guest handed back to the host are not
// ("warm" and "cold" in docs/performance.md, session 29); the optional argument is the block's
// size in MiB (default 8; 40 asks for 20 huge pages, more than a previous run freed). The
// populated pages are also touched afterwards, twice: how much of the first touch's cost a
// populate spares on this host (on session 42's, about half). Not part
// of the build:
//   g++ -O2 -pthread -o /tmp/fault-cost scripts/fault-cost.cpp && /tmp/fault-cost; sleep 5; /tmp/fault-cost 40
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

namespace {
using Clock = std::chrono::steady_clock;
constexpr size_t kHuge = size_t(2) << 20;

double msSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count() * 1e3; }

/// A fresh anonymous block of @p bytes (a multiple of 2 MiB) on a 2 MiB boundary, advised as asked.
char* freshBlock(size_t bytes, int advice, char*& raw) {
    raw = static_cast<char*>(mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    if (raw == MAP_FAILED) return nullptr;
    char* p = reinterpret_cast<char*>((reinterpret_cast<size_t>(raw) + kHuge - 1) / kHuge * kHuge);
    madvise(p, bytes, advice);
    return p;
}

void touch(char* p, size_t bytes) {
    for (size_t i = 0; i < bytes; i += 4096) p[i] = 1;
}
}  // namespace

int main(int argc, char** argv) {
    const long mib = argc > 1 ? std::atol(argv[1]) : 8;
    if (mib < 2 || mib % 2 != 0) return std::fprintf(stderr, "usage: fault-cost [MiB, even, at least 2]\n"), 2;
    const size_t bytes = size_t(mib) << 20;
    char* raw = nullptr;
    char* p = freshBlock(bytes, MADV_NOHUGEPAGE, raw);
    if (!p) return 1;
    auto t = Clock::now();
    touch(p, bytes);
    const double small1 = msSince(t);
    munmap(raw, bytes + kHuge);

    p = freshBlock(bytes, MADV_NOHUGEPAGE, raw);
    t = Clock::now();
    std::thread a([&] { touch(p, bytes / 2); }), b([&] { touch(p + bytes / 2, bytes / 2); });
    a.join(), b.join();
    const double small2 = msSince(t);
    munmap(raw, bytes + kHuge);

    p = freshBlock(bytes, MADV_NOHUGEPAGE, raw);
    t = Clock::now();
    const int rc = madvise(p, bytes, MADV_POPULATE_WRITE);
    const double populate = msSince(t);
    // The same pages touched after they were populated, then once more: on a host that maps a
    // guest's pages at their first touch (a PVM guest: session 42) the first touch after the
    // populate still costs about half a fault; the second touch is free.
    t = Clock::now();
    touch(p, bytes);
    const double afterPopulate = msSince(t);
    t = Clock::now();
    touch(p, bytes);
    const double again = msSince(t);
    munmap(raw, bytes + kHuge);

    p = freshBlock(bytes, MADV_HUGEPAGE, raw);
    t = Clock::now();
    touch(p, bytes);
    const double huge = msSince(t);
    munmap(raw, bytes + kHuge);

    const double pages = double(bytes) / 4096.0, hugePages = double(bytes) / double(kHuge);
    std::printf("%ld MiB of fresh memory:\n", mib);
    std::printf("  4 KiB pages touched, one thread   %7.2f ms  (%5.1f us a page)\n", small1, small1 * 1e3 / pages);
    std::printf("  4 KiB pages touched, two threads  %7.2f ms  (%5.1f us a page)\n", small2, small2 * 1e3 / pages);
    std::printf("  4 KiB pages, MADV_POPULATE_WRITE  %7.2f ms  (%5.2f us a page)%s\n", populate, populate * 1e3 / pages,
                rc == 0 ? "" : "  (not supported here)");
    std::printf("  the populated pages touched        %7.2f ms  (%5.2f us a page)\n", afterPopulate, afterPopulate * 1e3 / pages);
    std::printf("  and touched again                 %7.2f ms  (%5.2f us a page)\n", again, again * 1e3 / pages);
    std::printf("  huge pages touched, one thread    %7.2f ms  (%5.0f us a huge page)\n", huge, huge * 1e3 / hugePages);
    return 0;
}
