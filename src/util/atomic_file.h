// util/atomic_file.h — writing whole output files without ever leaving a partial file or
// clobbering something that is not ours: a regular file (or a missing one) is written as a
// temporary file beside the target and renamed over it; a symbolic link is written through
// (its final target is the file that is replaced, the link stays); a device node or FIFO
// (/dev/stdout, /dev/null) is never replaced — text is streamed into it, binary outputs
// refuse it. Owns the output-path rules every writer (images, .vdb, JSON, tables) follows.
#pragma once
#include <string>

namespace vdbsplat {

/// What an output path currently names, after following symbolic links.
enum class OutputKind {
    Missing,  ///< nothing there yet: a new regular file
    Regular,  ///< an existing regular file: replaced atomically
    Special,  ///< a character/block device, FIFO or socket: streamed into, never replaced
};

/// @brief Throws Error "<out>: output directory '<dir>' does not exist" when the folder
/// of @p out is missing: checked before any work, so a bad -o costs nothing.
void checkOutputDirectory(const std::string& out);

/// @brief The file a write to @p path really replaces: @p path itself, or the final target
/// of a symbolic link (relative links resolved against the link's folder); a link through
/// /proc (/dev/stdout → /proc/self/fd/1) is returned as is (it is Special: only opening
/// it by name reaches the right file, pipe or terminal).
/// @throw Error naming @p path for a dangling link, a link loop or a directory.
std::string resolveOutputPath(const std::string& path);

/// @brief Classifies @p path (following links) for writing; checks its folder exists.
/// @throw Error naming @p path as resolveOutputPath does, or for a missing folder.
OutputKind checkOutputPath(const std::string& path);

/// @brief checkOutputPath, and refuses a Special target: for binary outputs (images, .vdb)
/// that need a seekable regular file. @p flag (e.g. "-o") prefixes the message when given.
void checkRegularOutputPath(const std::string& path, const std::string& flag = "");

/// @brief Refuses an output that would replace one of the command's inputs: the same file
/// through any path, symbolic link or hard link (render --stats IN.vdb, bench --json IN.vdb).
/// @throw Error "<flag>: <output>: is the input file <input>" when they are the same file.
void checkNotAnInput(const std::string& output, const std::string& input, const std::string& flag);

/// @brief A temporary name beside @p target (same folder, so rename is atomic), ending in
/// @p suffix (the image writers keep the extension last).
std::string temporaryPathFor(const std::string& target, const std::string& suffix = "");

/// @brief Renames @p tmp onto @p target; removes @p tmp and throws Error naming
/// @p userPath on failure.
void renameIntoPlace(const std::string& tmp, const std::string& target, const std::string& userPath);

/// @brief Writes @p text to @p path: atomically for a regular or missing file (through a
/// symbolic link to its target), streamed for a device node or FIFO (a FIFO without a
/// reader is an error, not a hang).
/// @throw Error naming @p path when the folder is missing or the write fails.
void writeTextFileAtomic(const std::string& path, const std::string& text);

}  // namespace vdbsplat
