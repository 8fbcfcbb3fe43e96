// cli/cmd_bench.cpp — `vdbsplat bench` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runBench(const Argv&) { throw Error("'bench' is not implemented yet"); }
}  // namespace vdbsplat::cli
