// tests/fuzz/fuzz_image.cpp — libFuzzer target: `vdbsplat compare`'s input (readImage,
// PNG through libpng, EXR through OpenEXR, chosen by content). The first
// byte picks the extension. Findings inside libpng/OpenEXR are reported, not ours to fix.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "image/image.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const std::string path = vdbsplat::fuzz::scratchFile(data + 1, size - 1, data[0] & 1 ? ".exr" : ".png");
    try {
        vdbsplat::readImage(path);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
