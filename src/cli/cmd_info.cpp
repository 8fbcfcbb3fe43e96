// cli/cmd_info.cpp — `vdbsplat info` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runInfo(const Argv&) { throw Error("'info' is not implemented yet"); }
}  // namespace vdbsplat::cli
