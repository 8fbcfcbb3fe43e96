// volume/leaf_values.cpp — sanitizeLeafValues with Google Highway (see leaf_values.h). Compiled
// once per SIMD target (foreach_target.h); HWY_DYNAMIC_DISPATCH picks the best the CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "volume/leaf_values.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "volume/leaf_values.h"

#ifndef VDBSPLAT_LEAF_VALUES_CONSTANTS  // this file is compiled once per target: define them once
#define VDBSPLAT_LEAF_VALUES_CONSTANTS
namespace vdbsplat {
namespace {
constexpr int kWords = 8;  // 512 values, 64 per mask word
constexpr float kHigh = std::numeric_limits<float>::max(), kLow = std::numeric_limits<float>::lowest();
}  // namespace
}  // namespace vdbsplat
#endif

HWY_BEFORE_NAMESPACE();
namespace vdbsplat {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

uint64_t SanitizeLeafValues(float* values, uint64_t* maskWords, float& lo, float& hi) {
    const hn::CappedTag<float, 16> d;
    const size_t n = hn::Lanes(d);
    if (n < 8) return sanitizeLeafValuesScalar(values, maskWords, lo, hi);  // a vector's bits: whole bytes
    using V = hn::Vec<decltype(d)>;
    const V high = hn::Set(d, kHigh), low = hn::Set(d, kLow);
    V vLo = high, vHi = low;
    uint64_t count = 0;
    const uint64_t laneBits = n == 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1;
    for (int w = 0; w < kWords; ++w) {
        uint64_t& word = maskWords[w];
        for (size_t i = 0; i < 64 && (word >> i) != 0; i += n) {
            const uint64_t bits = (word >> i) & laneBits;
            if (bits == 0) continue;
            uint8_t bytes[8];
            for (int k = 0; k < 8; ++k) bytes[k] = uint8_t(bits >> (8 * k));
            auto active = hn::LoadMaskBits(d, bytes);
            float* p = values + 64 * w + i;
            V v = hn::LoadU(d, p);
            const auto bad = hn::AndNot(hn::IsFinite(v), active);  // active and not finite
            if (!hn::AllFalse(d, bad)) {
                count += hn::CountTrue(d, bad);
                v = hn::IfThenZeroElse(bad, v);
                hn::StoreU(v, d, p);
                uint8_t badBytes[8] = {};
                hn::StoreMaskBits(d, bad, badBytes);
                uint64_t cleared = 0;
                for (int k = 0; k < 8; ++k) cleared |= uint64_t(badBytes[k]) << (8 * k);
                word &= ~((cleared & laneBits) << i);
                active = hn::AndNot(bad, active);
            }
            vLo = hn::Min(vLo, hn::IfThenElse(active, v, high));
            vHi = hn::Max(vHi, hn::IfThenElse(active, v, low));
        }
    }
    lo = hn::GetLane(hn::MinOfLanes(d, vLo));
    hi = hn::GetLane(hn::MaxOfLanes(d, vHi));
    // No active value: the identities stay, lo > hi (as the scalar pass leaves them).
    return count;
}

}  // namespace HWY_NAMESPACE
}  // namespace vdbsplat
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vdbsplat {

HWY_EXPORT(SanitizeLeafValues);

uint64_t sanitizeLeafValues(float* values, uint64_t* maskWords, float& lo, float& hi) {
    return HWY_DYNAMIC_DISPATCH(SanitizeLeafValues)(values, maskWords, lo, hi);
}

uint64_t sanitizeLeafValuesScalar(float* values, uint64_t* maskWords, float& lo, float& hi) {
    uint64_t count = 0;
    lo = kHigh, hi = kLow;
    for (int w = 0; w < kWords; ++w)
        for (uint64_t on = maskWords[w]; on != 0; on &= on - 1) {
            const int b = std::countr_zero(on);
            float& x = values[64 * w + b];
            if (!std::isfinite(x)) {
                x = 0.0f;
                ++count;
                maskWords[w] &= ~(uint64_t(1) << b);
                continue;
            }
            lo = std::min(lo, x);
            hi = std::max(hi, x);
        }
    return count;
}

}  // namespace vdbsplat
#endif  // HWY_ONCE
