// util/atomic_file.cpp — temporary file + rename (see atomic_file.h).
#include "util/atomic_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "util/error.h"

namespace vdbsplat {

void checkOutputDirectory(const std::string& out) {
    const std::filesystem::path dir = std::filesystem::path(out).parent_path();
    std::error_code ec;
    if (!dir.empty() && !std::filesystem::is_directory(dir, ec))
        throw Error(out + ": output directory '" + dir.string() + "' does not exist");
}

void writeTextFileAtomic(const std::string& path, const std::string& text) {
    const std::string tmp = path + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(path + ": cannot open for writing");
        out << text;
        out.flush();
        if (!out) {
            std::remove(tmp.c_str());
            throw Error(path + ": write failed");
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::remove(tmp.c_str());
        throw Error(path + ": cannot rename temporary file into place: " + ec.message());
    }
}

}  // namespace vdbsplat
