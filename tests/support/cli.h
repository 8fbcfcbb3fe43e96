// tests/support/cli.h — shared by the tests that run the real `vdbsplat` binary (header
// only, like error_of.h): whole-file reads and writes, a scratch folder removed afterwards,
// one run of the binary with its exit code and output captured, and the one-line error
// contract of every command (non-zero exit, exactly one stderr line "vdbsplat: error: …"
// naming the file or flag, nothing on stdout, no temporary left behind).
#pragma once
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace vdbsplat::test {

namespace fs = std::filesystem;

/// @brief The whole content of @p p ("" when it cannot be read).
/// The lines of @p text, without their newlines.
inline std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream s(text);
    for (std::string l; std::getline(s, l);) out.push_back(l);
    return out;
}

/// The comma-separated fields of one CSV line (no quoting), a trailing empty field included.
inline std::vector<std::string> fields(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) out.push_back(f);
    if (!line.empty() && line.back() == ',') out.push_back("");
    return out;
}

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

/// @brief Starts `vdbsplat ARGS` without a shell, SIGINT and SIGTERM at their default (as in
/// a terminal: a shell's background job would ignore SIGINT), stdout and stderr to files.
/// @return the child's pid (0 when it could not be started; a test failure is added).
inline pid_t spawnVdbsplat(std::vector<std::string> args, const std::string& outPath, const std::string& errPath) {
    args.insert(args.begin(), VDBSPLAT_BINARY);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    if (posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), environ) != 0) {
        ADD_FAILURE() << "posix_spawn " << argv[0] << " failed";
        pid = 0;
    }
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    return pid;
}

/// @brief Waits (at most @p boundSeconds) until process @p pid catches signal @p sig, read
/// from /proc/PID/status "SigCgt", so a test's signal finds the handler and not the default.
/// @return false when it never did.
inline bool waitForHandler(pid_t pid, int sig, int boundSeconds) {
    for (int i = 0; i < boundSeconds * 50; ++i) {
        std::ifstream status("/proc/" + std::to_string(pid) + "/status");
        for (std::string line; std::getline(status, line);)
            if (line.rfind("SigCgt:", 0) == 0 && (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1u)
                return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
}

/// @brief Waits for @p pid; kills it (SIGKILL) when it has not ended within @p boundSeconds,
/// a bound on time, never a timed assertion. @return the wait status.
inline int waitBounded(pid_t pid, int boundSeconds) {
    int status = 0;
    for (int i = 0; i < boundSeconds * 20; ++i) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) return status;
        if (r < 0 && errno != EINTR) return status;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "pid " << pid << " still running after " << boundSeconds << " s: killed";
    ::kill(pid, SIGKILL);
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
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
