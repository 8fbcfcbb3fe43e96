// cli/cmd_tables.cpp — `vdbsplat tables`: regenerate (--out DIR) or verify (--check [DIR])
// the footprint and reindex tables (DESIGN §3; footprint/tables.h).
#include <cstdio>
#include <iostream>

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "footprint/kernel.h"
#include "footprint/tables.h"
#include "util/error.h"

namespace vdbsplat::cli {

namespace {

int writeTables(const std::string& dir) {
    for (const KernelShape* kernel : {&KernelShape::standard(), &KernelShape::sharp()}) {
        const Tables k = buildTables(*kernel);
        saveTables(k, dir);
        std::printf("wrote %s/%s (kernel %s, %d intervals in d², max error %.3e)\n", dir.c_str(),
                    footprintTableFile(*kernel).c_str(), kernel->tableName(), k.footprint.intervals(),
                    k.footprint.maxAbsError());
    }
    const Tables t = buildTables();
    std::printf("wrote %s/%s (%d × %d intervals in i² × α ∈ [0°, %g°], max error %.3e)\n", dir.c_str(),
                kReindexTableFile, t.reindex.intervalsI2(), t.reindex.intervalsAlpha(), t.reindex.alphaMaxDeg(),
                t.reindex.maxAbsError());
    return 0;
}
}  // namespace

void declareTables(CLI::App& app) {
    app.description(
        "regenerate or check the footprint and reindex tables\n"
        "\n"
        "usage: vdbsplat tables --out DIR | --check [DIR]\n"
        "\n"
        "The footprint table is F(d²), the kernel's line integral at normalised ray-centre\n"
        "distance d; the reindex table is d²(i², α) for α in [0°, 15°] (DESIGN §3).");
    addPositional(app, "DIR", "with --check: the folder to verify (default: the shipped tables/)");
    addValueFlag(app, "--out", "DIR", "write footprint.table, footprint-gaussian-sharp.table (one per\n"
                                      "--kernel) and reindex.table into DIR");
    addSwitch(app, "--check", "verify DIR: header, kernel, checksum, and byte-for-byte equality\n"
                              "with a fresh build; exits non-zero on any mismatch");
}

int runTables(const Args& args) {
    const bool check = args.has("--check"), out = args.has("--out");
    if (check == out) throw Error("tables: give exactly one of --out DIR or --check [DIR] (see --help)");
    if (out) {
        if (!args.positionals().empty()) throw Error("tables --out: unexpected argument '" + args.positionals()[0] + "'");
        return writeTables(*args.get("--out"));
    }
    if (args.positionals().size() > 1) throw Error("tables --check: expected at most one directory");
    const std::filesystem::path dir = args.positionals().empty() ? defaultTablesDir() : std::filesystem::path(args.positionals()[0]);
    for (const std::string& line : checkTables(dir)) std::cout << line << "\n";
    return 0;
}

}  // namespace vdbsplat::cli
