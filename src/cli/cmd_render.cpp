// cli/cmd_render.cpp — `vdbsplat render` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runRender(const Argv&) { throw Error("'render' is not implemented yet"); }
}  // namespace vdbsplat::cli
