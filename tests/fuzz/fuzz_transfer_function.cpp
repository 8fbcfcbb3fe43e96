// tests/fuzz/fuzz_transfer_function.cpp — libFuzzer target: transfer-function JSON (the
// vdbsplat format and ParaView colour maps) through TransferFunction::fromJson. Every input
// must end in a valid TransferFunction or a vdbsplat::Error; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "util/error.h"
#include "volume/transfer_function.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        const auto tf = vdbsplat::TransferFunction::fromJson(std::string(reinterpret_cast<const char*>(data), size),
                                                             "fuzz.json");
        (void)tf.bake(0.f, 1.f, 1.0);
        (void)tf.toJson();
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
