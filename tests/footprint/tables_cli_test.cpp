// tests/footprint/tables_cli_test.cpp — `vdbsplat tables --check` passes on the shipped
// tables and fails (non-zero, one line naming the file) on a corrupted copy; --out
// regenerates files that then check clean.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "footprint/tables.h"
#include "support/cli.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::CliResult;

/// Runs `vdbsplat ARGS` with its output captured in a scratch folder of its own.
CliResult run(const std::string& args) {
    const test::ScratchDir logs("tables-log");
    return test::runVdbsplat(args, logs.dir());
}

TEST(TablesCli, CheckPassesOnShippedTables) {
    const CliResult r = run("tables --check");
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(run("tables --check " + defaultTablesDir().string()).rc, 0);
    EXPECT_EQ(run("tables --help").rc, 0);
}

TEST(TablesCli, CheckFailsOnACorruptedCopy) {
    const test::ScratchDir scratch("tables-corrupt");
    const fs::path& dir = scratch.dir();
    for (const char* f : {kFootprintTableFile, kReindexTableFile}) fs::copy_file(defaultTablesDir() / f, dir / f);
    {
        std::fstream io(dir / kReindexTableFile, std::ios::in | std::ios::out | std::ios::binary);
        io.seekp(-11, std::ios::end);
        io.put('\x7f');
    }
    const CliResult r = run("tables --check " + dir.string());
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find((dir / kReindexTableFile).string()), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
}

TEST(TablesCli, OutRegeneratesIdenticalFiles) {
    const test::ScratchDir scratch("tables-out");
    const std::string dir = scratch.path("tables");
    EXPECT_EQ(run("tables --out " + dir).rc, 0);
    EXPECT_EQ(run("tables --check " + dir).rc, 0);
}

TEST(TablesCli, BadUsageIsRejected) {
    const test::ScratchDir scratch("tables-bad");
    EXPECT_NE(run("tables").rc, 0);
    EXPECT_NE(run("tables --check --out x").rc, 0);
    EXPECT_NE(run("tables --check " + scratch.path("missing")).rc, 0);
}

}  // namespace
}  // namespace vdbsplat
