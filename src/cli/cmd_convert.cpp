// cli/cmd_convert.cpp — `vdbsplat convert` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runConvert(const Argv&) { throw Error("'convert' is not implemented yet"); }
}  // namespace vdbsplat::cli
