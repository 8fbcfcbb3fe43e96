// tests/fuzz/fuzz_tables.cpp — libFuzzer target: footprint and reindex table files
// (parseFootprintTable / parseReindexTable). The first byte picks the parser.
#include <cstddef>
#include <cstdint>
#include <string>

#include "footprint/tables.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        if (data[0] & 1) vdbsplat::parseReindexTable(bytes, "reindex.table");
        else vdbsplat::parseFootprintTable(bytes, "footprint.table");
    } catch (const vdbsplat::Error&) {
    }
    return 0;
}
