// tests/support/targets.h — run a test body on every SIMD target the binary holds.
#pragma once
#include <gtest/gtest.h>
#include <hwy/targets.h>

namespace vdbsplat::test {

/// Runs @p body once per SIMD target compiled in (foreach_target) that this CPU supports, each
/// chosen by the runtime dispatch in turn (SSE4, AVX2, AVX-512, and the scalar fallback on x86),
/// then restores the best one: CI's machine would otherwise test only its widest vectors.
template <class F>
void forEachTarget(F body) {
    const int64_t targets = hwy::SupportedTargets() & HWY_TARGETS;
    for (int64_t rest = targets; rest != 0; rest &= rest - 1) {
        const int64_t target = rest & -rest;
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(hwy::TargetName(target));
        body();
    }
    hwy::SetSupportedTargetsForTest(0);  // back to what the CPU has
}

}  // namespace vdbsplat::test
