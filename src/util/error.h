// util/error.h — the one exception type vdbsplat throws for bad input.
// Owns: vdbsplat::Error. Everything below the command line reports bad input by
// throwing it with a one-line message that names the file or flag and the
// problem; src/cli/main.cpp catches it and prints "vdbsplat: error: <what>".
#pragma once
#include <stdexcept>
#include <string>

namespace vdbsplat {

/// @brief A user-facing failure (bad file, bad flag, bad value). One line, no trailing newline.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace vdbsplat
