// tests/fuzz/fuzz_vdb.cpp — libFuzzer target: the .vdb path of `vdbsplat info` and
// `render` — vdbsplat's own reader (readVdbGrid, on the bytes), the structural pre-check
// (checkVdbStructure), the load (loadVolume: the own reader, or for what it leaves to
// OpenVDB the trial read in a forked child), and the description (describeFile, OpenVDB's
// read in a forked child). The child's crash on OpenVDB's known heap corruption is an
// Error by design; a crash here is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_support.h"
#include "util/error.h"
#include "volume/grid.h"
#include "volume/vdb_check.h"
#include "volume/vdb_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)vdbsplat::readVdbGrid(reinterpret_cast<const char*>(data), size, "fuzz.vdb", "");
    } catch (const vdbsplat::Error&) {
    }
    const std::string path = vdbsplat::fuzz::scratchFile(data, size, ".vdb");
    try {
        (void)vdbsplat::loadVolume(path);
    } catch (const vdbsplat::Error&) {
    }
    try {
        vdbsplat::checkVdbStructure(path);
        (void)vdbsplat::describeFile(path);
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
