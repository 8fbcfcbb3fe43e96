// tests/fuzz/fuzz_study_spec.cpp — libFuzzer target: `vdbsplat study --spec` files
// (study/spec.h) through parseSpec. Every input must end in arguments or a vdbsplat::Error; a
// crash, hang or sanitizer report is a finding. (The arguments then go through the study's
// flag parser, which the CLI tests cover.)
#include <cstddef>
#include <cstdint>
#include <string>

#include "study/spec.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace vdbsplat;
    try {
        size_t n = 0;
        for (const auto& a : study::parseSpec(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json"))
            n += a.args.size();
        (void)n;
    } catch (const Error&) {
    }
    return 0;
}
