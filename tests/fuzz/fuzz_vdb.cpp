// tests/fuzz/fuzz_vdb.cpp — libFuzzer target: the .vdb path of `vdbsplat info` and
// `render` — the structural pre-check (checkVdbStructure), the trial read in a forked
// child, then OpenVDB's read and the description (describeFile). The child's crash on
// OpenVDB's known heap corruption is an Error by design; a crash here is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "util/error.h"
#include "volume/grid.h"
#include "volume/vdb_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = vdbsplat::fuzz::scratchFile(data, size, ".vdb");
    try {
        vdbsplat::checkVdbStructure(path);
        (void)vdbsplat::describeFile(path);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
