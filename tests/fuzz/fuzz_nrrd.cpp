// tests/fuzz/fuzz_nrrd.cpp — libFuzzer target: `vdbsplat convert`'s NRRD reader (convertNrrd).
// The input is the whole .nrrd file (header and attached data); a detached "data file" is
// resolved as the reader resolves it (beside the scratch file, or an absolute path).
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "util/error.h"
#include "volume/nrrd.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = vdbsplat::fuzz::scratchFile(data, size, ".nrrd");
    vdbsplat::ConvertOptions options;
    options.maxVoxels = uint64_t(1) << 20;  // the bound is tested in tests/; here: stay fast
    try {
        vdbsplat::convertNrrd(path, options);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
