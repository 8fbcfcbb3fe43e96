// tests/fuzz/fuzz_vti.cpp — libFuzzer target: `vdbsplat convert`'s VTK ImageData reader
// (convertVti). The input is the whole .vti file: XML, inline data and appended block.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "util/error.h"
#include "volume/vti.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = vdbsplat::fuzz::scratchFile(data, size, ".vti");
    vdbsplat::ConvertOptions options;
    options.maxVoxels = uint64_t(1) << 20;  // the bound is tested in tests/; here: stay fast
    try {
        vdbsplat::convertVti(path, options);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
