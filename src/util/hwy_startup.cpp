// util/hwy_startup.cpp — linked into every executable (CMake: vdbsplat_add_startup), not into
// the core library. Owns: the process's definition of hwy::platform::TimerResolution, which
// keeps libhwy's static initialiser from spending ~6 ms of every vdbsplat process measuring a
// timer that vdbsplat never reads.
//
// Why: before google/highway#2440 (merged January 2025) Highway initialised a namespace-scope
// constant of its nanobenchmark with platform::TimerResolution() when libhwy.so is loaded:
// repeated back-to-back timer reads, 6–9 ms of CPU per process on the 2-core machine
// (docs/performance.md, session 17; a program linking only libhwy: 7.9 ms against 0.5 ms for an
// empty one). Debian's libhwy 1.0.3 still makes the call at load. libhwy calls the
// function through its PLT, so the definition the dynamic loader finds first wins: this one,
// exported from the executable (--export-dynamic-symbol), which is first in the lookup order.
//
// What it changes: only hwy::Measure (nanobenchmark) reads the value, and vdbsplat calls
// neither Measure nor anything else of nanobenchmark (its benchmarks use Google Benchmark); the
// runtime dispatch (SupportedTargets, GetChosenTarget) is untouched. With a libhwy that makes the
// call lazily the definition is simply never called. tests/util/test_hwy_startup.cpp checks
// that the executable exports it and that it is the one the process resolves.
#include <hwy/nanobenchmark.h>

#include <cstdint>

#include "util/hwy_startup.h"

namespace hwy {
namespace platform {

/// A fixed answer in place of the measurement (util/hwy_startup.h).
uint64_t TimerResolution() { return vdbsplat::kHwyTimerResolutionTicks; }

}  // namespace platform
}  // namespace hwy
