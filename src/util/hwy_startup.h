// util/hwy_startup.h — what util/hwy_startup.cpp answers in place of libhwy's timer measurement
// (the file's header says why every executable links it).
#pragma once
#include <cstdint>

namespace vdbsplat {

/// hwy::platform::TimerResolution() in every vdbsplat executable: a fixed tick count (x86's TSC
/// read back to back is a few tens of ticks) instead of libhwy's measurement at load time.
inline constexpr uint64_t kHwyTimerResolutionTicks = 32;

}  // namespace vdbsplat
