// tests/footprint/tables_cli_test.cpp — `vdbsplat tables --check` passes on the shipped
// tables and fails (non-zero, one line naming the file) on a corrupted copy; --out
// regenerates files that then check clean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "footprint/tables.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;

struct CliRun {
    int rc;
    std::string err;
};

CliRun run(const std::string& args) {
    const fs::path err = fs::temp_directory_path() / ("vdbsplat_cli_err_" + std::to_string(::getpid()));
    const std::string cmd = std::string(VDBSPLAT_BINARY) + " " + args + " >/dev/null 2>" + err.string();
    const int status = std::system(cmd.c_str());
    std::ifstream in(err);
    std::ostringstream s;
    s << in.rdbuf();
    fs::remove(err);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

fs::path tempDir(const std::string& tag) {
    const fs::path dir = fs::temp_directory_path() / ("vdbsplat_cli_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

TEST(TablesCli, CheckPassesOnShippedTables) {
    const CliRun r = run("tables --check");
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(run("tables --check " + defaultTablesDir().string()).rc, 0);
    EXPECT_EQ(run("tables --help").rc, 0);
}

TEST(TablesCli, CheckFailsOnACorruptedCopy) {
    const fs::path dir = tempDir("corrupt");
    fs::create_directories(dir);
    for (const char* f : {kFootprintTableFile, kReindexTableFile}) fs::copy_file(defaultTablesDir() / f, dir / f);
    {
        std::fstream io(dir / kReindexTableFile, std::ios::in | std::ios::out | std::ios::binary);
        io.seekp(-11, std::ios::end);
        io.put('\x7f');
    }
    const CliRun r = run("tables --check " + dir.string());
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find((dir / kReindexTableFile).string()), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    fs::remove_all(dir);
}

TEST(TablesCli, OutRegeneratesIdenticalFiles) {
    const fs::path dir = tempDir("out");
    EXPECT_EQ(run("tables --out " + dir.string()).rc, 0);
    EXPECT_EQ(run("tables --check " + dir.string()).rc, 0);
    fs::remove_all(dir);
}

TEST(TablesCli, BadUsageIsRejected) {
    EXPECT_NE(run("tables").rc, 0);
    EXPECT_NE(run("tables --check --out x").rc, 0);
    EXPECT_NE(run("tables --check " + tempDir("missing").string()).rc, 0);
}

}  // namespace
}  // namespace vdbsplat
