// cli/cmd_info.cpp — `vdbsplat info FILE.vdb`: prints every grid of a file.
// Owns: the flags of the info command; the description is volume/describe.cpp.
#include <iostream>

#include "cli/args.h"
#include "cli/commands.h"
#include "volume/grid.h"

namespace vdbsplat::cli {

namespace {
const char* kHelp =
    "usage: vdbsplat info FILE.vdb\n"
    "\n"
    "Prints every grid of FILE.vdb: name, value type, class, active voxel count, index and\n"
    "world bounding boxes, voxel size, the index-to-world transform, and the value range of\n"
    "float and double grids.\n";
}  // namespace

int runInfo(const Argv& argv) {
    const Args args(argv, {}, {});
    if (args.wantsHelp()) {
        std::cout << kHelp;
        return 0;
    }
    std::cout << describeFile(args.onePositional("FILE.vdb"));
    return 0;
}

}  // namespace vdbsplat::cli
