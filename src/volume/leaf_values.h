// volume/leaf_values.h — one leaf's values as the reader lands them, vectorised.
// Owns: sanitizeLeafValues, which zeroes a leaf's non-finite active values (clearing their mask
// bits and counting them) and measures the range of the rest in one pass, a vector of values at a
// time (Google Highway, runtime dispatch); and sanitizeLeafValuesScalar, the bit-by-bit loops
// the reader used before (session 19), kept as the oracle the tests hold it to and as the path
// of targets whose vectors hold fewer than 8 floats.
#pragma once
#include <cstdint>

namespace vdbsplat {

/// @brief For the 512 @p values of one leaf and its active mask @p maskWords (8 words, bit b of
/// word w: value 64·w + b): sets every non-finite active value to 0 and clears its bit, returns
/// how many; @p lo and @p hi get the least and greatest remaining active value (lo > hi: none).
/// Which of two equal extremes is kept is unspecified, so a 0 extreme may be +0 or −0: a caller
/// that must tell them apart measures such a leaf again (the reader does, in mask order).
uint64_t sanitizeLeafValues(float* values, uint64_t* maskWords, float& lo, float& hi);

/// @brief The same, a value at a time in mask order (std::min/std::max: the first of equal
/// extremes kept).
uint64_t sanitizeLeafValuesScalar(float* values, uint64_t* maskWords, float& lo, float& hi);

}  // namespace vdbsplat
