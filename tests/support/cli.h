// tests/support/cli.h — shared by the tests that run the real `vdbsplat` binary (header
// only, like error_of.h): whole-file reads and writes, a scratch folder removed afterwards,
// one run of the binary with its exit code and output captured, and the one-line error
// contract of every command (non-zero exit, exactly one stderr line "vdbsplat: error: …"
// naming the file or flag, nothing on stdout, no temporary left behind).
#pragma once
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace vdbsplat::test {

namespace fs = std::filesystem;

/// @brief The whole content of @p p ("" when it cannot be read).
inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// @brief Writes @p bytes to @p p, replacing it.
inline void spit(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    EXPECT_TRUE(out.good()) << p;
}

/// @brief A fresh folder under the system temporary folder, removed with everything in it.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& tag) {
        std::string pattern = (fs::temp_directory_path() / ("vdbsplat-" + tag + "-XXXXXX")).string();
        if (::mkdtemp(pattern.data()) == nullptr) ADD_FAILURE() << "mkdtemp failed for " << pattern;
        dir_ = pattern;
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    const fs::path& dir() const { return dir_; }
    /// @brief The path of @p name inside the folder, as a string for command lines.
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

private:
    fs::path dir_;
};

/// @brief What one run of the binary did.
struct CliResult {
    int rc = -1;  ///< exit code; 128 + signal when it was killed
    std::string out, err;
};

/// @brief Runs `vdbsplat ARGS` through the shell (ARGS quoted by the caller); stdout and
/// stderr go through files in @p logDir. @p timeoutSeconds > 0 kills it after that long
/// (rc 124: a bound on time, never a timed assertion); @p shellPrefix runs first in the
/// same shell (e.g. "ulimit -f 8; ").
/// Runs the shell command @p command with stdout and stderr captured through files in @p logDir.
inline CliResult runShell(const std::string& command, const fs::path& logDir) {
    const fs::path out = logDir / "stdout.txt", err = logDir / "stderr.txt";
    const std::string cmd = command + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    fs::remove(out);
    fs::remove(err);
    return r;
}

inline CliResult runVdbsplat(const std::string& args, const fs::path& logDir, int timeoutSeconds = 0,
                             const std::string& shellPrefix = "") {
    const std::string timeout = timeoutSeconds > 0 ? "timeout -k 5 " + std::to_string(timeoutSeconds) + " " : "";
    return runShell(shellPrefix + timeout + "'" + VDBSPLAT_BINARY + "' " + args, logDir);
}

/// @brief The error contract: non-zero exit, exactly one stderr line "vdbsplat: error: …"
/// that contains @p needle, and nothing on stdout.
inline void expectOneLineError(const CliResult& r, const std::string& needle, const std::string& context = "") {
    EXPECT_NE(r.rc, 0) << context;
    EXPECT_EQ(r.err.rfind("vdbsplat: error: ", 0), 0u) << context << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << context << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << context << "\nexpected '" << needle << "' in: " << r.err;
    EXPECT_TRUE(r.out.empty()) << context << "\n" << r.out;
}

/// @brief No file in @p dir looks like an abandoned temporary (the atomic writers' ".tmp").
inline void expectNoTemporaries(const fs::path& dir) {
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

}  // namespace vdbsplat::test
