// cli/commands.h — the subcommands of the `vdbsplat` binary.
// Owns: two entry points per subcommand, each pair in its own cmd_*.cpp: declareX adds the
// command's usage, description and flags to its CLI::App (the one declaration of each flag;
// --help is generated from it), runX runs it with what was parsed, returns 0 on success and
// throws Error on bad input (main.cpp prints it). main.cpp lists the commands.
#pragma once
#include "cli/args.h"

namespace CLI {
class App;
}

namespace vdbsplat::cli {

void declareInfo(CLI::App& app);      ///< vdbsplat info FILE.vdb
void declareGenerate(CLI::App& app);  ///< vdbsplat generate KIND -o OUT.vdb …
void declareConvert(CLI::App& app);   ///< vdbsplat convert IN.raw[.gz] -o OUT.vdb …
void declareRender(CLI::App& app);    ///< vdbsplat render FILE.vdb -o OUT.png|exr …
void declareTables(CLI::App& app);    ///< vdbsplat tables --out DIR | --check
void declareBench(CLI::App& app);     ///< vdbsplat bench FILE.vdb …
void declareCompare(CLI::App& app);   ///< vdbsplat compare A B (PSNR, …)
void declareAnimate(CLI::App& app);   ///< vdbsplat animate FILE.vdb -o DIR (zoom, orbit or keyframes)
void declareStudy(CLI::App& app);     ///< vdbsplat study FILE.vdb… -o DIR (antialiasing study and report)

int runInfo(const Args& args);
int runGenerate(const Args& args);
int runConvert(const Args& args);
int runRender(const Args& args);
int runTables(const Args& args);
int runBench(const Args& args);
int runCompare(const Args& args);
int runAnimate(const Args& args);
int runStudy(const Args& args);

}  // namespace vdbsplat::cli
