// cli/cmd_tables.cpp — `vdbsplat tables` (placeholder until its issue lands).
#include "cli/commands.h"
#include "util/error.h"

namespace vdbsplat::cli {
int runTables(const Argv&) { throw Error("'tables' is not implemented yet"); }
}  // namespace vdbsplat::cli
