// cli/cmd_generate.cpp — `vdbsplat generate` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runGenerate(const Argv&) { throw Error("'generate' is not implemented yet"); }
}  // namespace vdbsplat::cli
