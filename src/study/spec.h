// study/spec.h — study files: a study's settings as JSON, kept beside the data and run again
// with `vdbsplat study --spec FILE.json -o DIR`.
// Owns: reading and checking the file (size, nesting, JSON, every key and its type) and turning
// it into the command-line arguments the study's own flag parser then validates, so a file and
// the same flags are checked (values, ranges, modes, kernels) by one parser. Format:
//   {"volumes": ["a.vdb", "b.vdb"], "modes": ["hybrid", "splat"], "kernels": ["gaussian"],
//    "views": ["standard", "ladder"], "base": 1, "distances": [2, 0.5], "size": [160, 160],
//    "spp": 16, "tf": "grey" (or "tfs": ["grey", "ct-bone"], one per volume), "grid": "density",
//    "threshold": 1, "lod": 1.25, "fov": 30,
//    "footprint": "auto", "filter_order": "postfilter", "subpixels": 1}
// Every key is optional except "volumes" (a non-empty array of paths; relative paths are
// relative to the working directory, as on the command line).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace vdbsplat::study {

/// Largest study file accepted, and its deepest JSON nesting ({"size": [w, h]} is 2).
inline constexpr size_t kMaxSpecBytes = 1u << 20;
inline constexpr int kMaxSpecNesting = 2;

/// One argument that came from the file, with the key it came from (for error messages).
struct SpecArgument {
    std::string key;                ///< "volumes", "modes", …
    std::vector<std::string> args;  ///< a positional path, or {"--flag", "value"}
};

/// @brief The arguments study file @p text (named @p name in messages) stands for.
/// @throw Error "<name>: …" naming the key for an oversized or too deeply nested file, invalid
/// JSON, a non-object, an unknown key, a wrong type, an empty list or string, a list item with a
/// comma (lists are comma-joined), a non-finite number, or missing volumes.
std::vector<SpecArgument> parseSpec(const std::string& text, const std::string& name);

/// @brief parseSpec of the file at @p path. @throw Error naming @p path when it cannot be read.
std::vector<SpecArgument> loadSpec(const std::string& path);

}  // namespace vdbsplat::study
