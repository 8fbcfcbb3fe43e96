// cli/cmd_compare.cpp — `vdbsplat compare` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runCompare(const Argv&) { throw Error("'compare' is not implemented yet"); }
}  // namespace vdbsplat::cli
