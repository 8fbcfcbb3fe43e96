// tests/fuzz/fuzz_support.h — shared by the libFuzzer targets (header only): a scratch file
// per process that the loaders under test read (they take paths, not buffers).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace vdbsplat::fuzz {

/// Writes @p size bytes to a per-process file ending in @p suffix and returns its path.
inline std::string scratchFile(const uint8_t* data, size_t size, const std::string& suffix) {
    const char* dir = std::getenv("TMPDIR");
    const std::string path = std::string(dir && *dir ? dir : "/tmp") + "/vdbsplat-fuzz-" +
                             std::to_string(::getpid()) + suffix;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path;
}

}  // namespace vdbsplat::fuzz
