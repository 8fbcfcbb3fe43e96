// util/atomic_file.h — writing whole files (JSON stats, tables) without ever
// leaving a partial file: write a temporary file beside the target, rename it.
#pragma once
#include <string>

namespace vdbsplat {

/// @brief Throws Error "<out>: output directory '<dir>' does not exist" when the folder
/// of @p out is missing: checked before any work, so a bad -o costs nothing.
void checkOutputDirectory(const std::string& out);

/// @brief Writes @p text to @p path atomically.
/// @throw Error naming the path when the folder is missing or the write fails.
void writeTextFileAtomic(const std::string& path, const std::string& text);

}  // namespace vdbsplat
