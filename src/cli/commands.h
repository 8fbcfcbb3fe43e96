// cli/commands.h — the subcommands of the `vdbsplat` binary.
// Owns: one entry point per subcommand, each in its own cmd_*.cpp. Each takes
// the arguments after the subcommand name, prints its --help when asked,
// returns 0 on success and throws Error on bad input (main.cpp prints it).
#pragma once
#include <string>
#include <vector>

namespace vdbsplat::cli {

using Argv = std::vector<std::string>;

int runInfo(const Argv& args);      ///< vdbsplat info FILE.vdb
int runGenerate(const Argv& args);  ///< vdbsplat generate KIND -o OUT.vdb …
int runConvert(const Argv& args);   ///< vdbsplat convert IN.raw[.gz] -o OUT.vdb …
int runRender(const Argv& args);    ///< vdbsplat render FILE.vdb -o OUT.png|exr …
int runTables(const Argv& args);    ///< vdbsplat tables --out DIR | --check
int runBench(const Argv& args);     ///< vdbsplat bench FILE.vdb …
int runCompare(const Argv& args);   ///< vdbsplat compare A B (PSNR, …)
int runAnimate(const Argv& args);   ///< vdbsplat animate FILE.vdb -o DIR (zoom, orbit or keyframes)
int runStudy(const Argv& args);     ///< vdbsplat study FILE.vdb… -o DIR (antialiasing study and report)

}  // namespace vdbsplat::cli
