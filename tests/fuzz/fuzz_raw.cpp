// tests/fuzz/fuzz_raw.cpp — libFuzzer target: `vdbsplat convert`'s raw / .gz reader
// (convertRaw). The first 4 bytes pick the dims (1..16 each) and type; the rest is the
// file, plain or gzip (the reader detects gzip by its magic bytes).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "util/error.h"
#include "volume/raw.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 4) return 0;
    vdbsplat::RawSpec spec;
    spec.dims = {1 + data[0] % 16, 1 + data[1] % 16, 1 + data[2] % 16};
    spec.type = data[3] % 3 == 0 ? vdbsplat::RawType::UInt8
                : data[3] % 3 == 1 ? vdbsplat::RawType::UInt16 : vdbsplat::RawType::Float32;
    spec.threshold = (data[3] >> 2) / 64.0;
    const std::string path = vdbsplat::fuzz::scratchFile(data + 4, size - 4, ".raw");
    try {
        vdbsplat::convertRaw(path, spec);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
