// cli/cmd_info.cpp — `vdbsplat info FILE.vdb`: prints every grid of a file.
// Owns: the flags of the info command; the description is volume/describe.cpp.
#include <iostream>

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "volume/grid.h"

namespace vdbsplat::cli {

void declareInfo(CLI::App& app) {
    app.description(
        "describe every grid in a .vdb file\n"
        "\n"
        "usage: vdbsplat info FILE.vdb\n"
        "\n"
        "Prints every grid of FILE.vdb: name, value type, class, active voxel count, index and\n"
        "world bounding boxes, voxel size, the index-to-world transform, and the value range of\n"
        "float and double grids.");
    addPositional(app, "FILE.vdb", "the file to describe");
}

int runInfo(const Args& args) {
    std::cout << describeFile(args.onePositional("FILE.vdb"));
    return 0;
}

}  // namespace vdbsplat::cli
