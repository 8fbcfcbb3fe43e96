// util/atomic_file.cpp — output-path rules, temporary file + rename (see atomic_file.h).
#include "util/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/error.h"

namespace vdbsplat {

namespace fs = std::filesystem;

namespace {

constexpr int kMaxLinkHops = 40;  ///< as the kernel's ELOOP limit

/// Writes all of @p text to the open descriptor @p fd; false on any error (errno set).
bool writeAll(int fd, const std::string& text) {
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        done += size_t(n);
    }
    return true;
}

/// Streams @p text into a device node, FIFO or /proc link such as /dev/stdout (opened by its
/// own name, so the kernel follows the links; never replaced, never truncated; appended to
/// when it is a regular file behind /dev/stdout, so earlier output there is kept).
void streamInto(const std::string& path, const std::string& text) {
    // O_NONBLOCK: a FIFO nobody reads fails with ENXIO instead of blocking forever.
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        throw Error(path + ": cannot open for writing: " +
                    (err == ENXIO ? std::string("a FIFO with no reader") : std::strerror(err)));
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    const bool ok = writeAll(fd, text);
    const int err = errno;
    ::close(fd);
    if (!ok) throw Error(path + ": write failed: " + std::strerror(err));
}

}  // namespace

void checkOutputDirectory(const std::string& out) {
    const fs::path dir = fs::path(out).parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw Error(out + ": output directory '" + dir.string() + "' does not exist");
}

namespace {

/// Follows the symbolic links of @p path textually; @p viaProc is set when a hop goes
/// through /proc (e.g. /dev/stdout → /proc/self/fd/1): those "magic" links name open files,
/// pipes or terminals, not paths, so only the kernel can follow them (by opening @p path).
fs::path followLinks(const std::string& path, bool& viaProc) {
    fs::path p = path;
    viaProc = false;
    std::error_code ec;
    for (int hop = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++hop) {
        if (hop == kMaxLinkHops) throw Error(path + ": too many levels of symbolic links");
        const fs::path target = fs::read_symlink(p, ec);
        if (ec) throw Error(path + ": cannot read symbolic link: " + ec.message());
        p = target.is_absolute() ? target : p.parent_path() / target;
        if (p.string().rfind("/proc/", 0) == 0) {
            viaProc = true;
            return p;
        }
    }
    return p;
}

}  // namespace

std::string resolveOutputPath(const std::string& path) {
    bool viaProc = false;
    const fs::path p = followLinks(path, viaProc);
    if (viaProc) return path;  // a magic link: written through by opening it (OutputKind::Special)
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (fs::is_directory(st)) throw Error(path + ": is a directory");
    if (p.string() != path && !fs::exists(st)) {
        const fs::path dir = p.parent_path();
        if (!dir.empty() && !fs::is_directory(dir, ec))
            throw Error(path + ": symbolic link to '" + p.string() + "', whose folder does not exist");
    }
    return p.string();
}

OutputKind checkOutputPath(const std::string& path) {
    checkOutputDirectory(path);
    bool viaProc = false;
    followLinks(path, viaProc);
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);  // the kernel follows every link
    if (fs::is_directory(st)) throw Error(path + ": is a directory");
    if (viaProc) return OutputKind::Special;
    if (fs::exists(st) && !fs::is_regular_file(st)) return OutputKind::Special;
    const std::string target = resolveOutputPath(path);
    return fs::exists(fs::status(target, ec)) ? OutputKind::Regular : OutputKind::Missing;
}

void checkRegularOutputPath(const std::string& path, const std::string& flag) {
    if (checkOutputPath(path) == OutputKind::Special)
        throw Error((flag.empty() ? "" : flag + ": ") + path +
                    ": is a device, FIFO or socket, not a regular file (this output is written only to files)");
}

std::string temporaryPathFor(const std::string& target, const std::string& suffix) {
    return target + ".tmp" + std::to_string(::getpid()) + suffix;
}

void renameIntoPlace(const std::string& tmp, const std::string& target, const std::string& userPath) {
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        std::remove(tmp.c_str());
        throw Error(userPath + ": cannot move the finished file into place: " + ec.message());
    }
}

void writeTextFileAtomic(const std::string& path, const std::string& text) {
    if (checkOutputPath(path) == OutputKind::Special) return streamInto(path, text);
    const std::string target = resolveOutputPath(path);
    const std::string tmp = temporaryPathFor(target);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw Error(path + ": cannot open for writing: " + std::strerror(errno));
    bool ok = writeAll(fd, text);
    int err = errno;
    if (::close(fd) != 0 && ok) {
        ok = false;
        err = errno;
    }
    if (!ok) {
        std::remove(tmp.c_str());
        throw Error(path + ": write failed: " + std::strerror(err));
    }
    renameIntoPlace(tmp, target, path);
}

void checkNotAnInput(const std::string& output, const std::string& input, const std::string& flag) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const bool same = fs::exists(output, ec) && fs::exists(input, ec) ? fs::equivalent(output, input, ec)
                                                                       : fs::weakly_canonical(output, ec) == fs::weakly_canonical(input, ec);
    if (same && !ec) throw Error(flag + ": " + output + ": is the input file " + input + " (it would be overwritten)");
}

}  // namespace vdbsplat
