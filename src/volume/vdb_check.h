// volume/vdb_check.h — a cheap structural pre-check of .vdb files before OpenVDB reads them.
// Owns: checkVdbStructure. OpenVDB 10 does not check its reads against the end of the
// file: a truncated file can make it take a string length from garbage (gigabyte
// allocations, megabyte error messages) or report "0 grids". This walks the header,
// the file metadata and every grid descriptor (all length-prefixed) and checks that
// each grid's recorded end offset lies inside the file, reading only a few hundred bytes.
// Also owns checkVdbFile (exists, regular, the pre-check: what every load does first),
// openVdbFile (checkVdbFile, then OpenVDB's open), OpenVdbLogCapture, which
// keeps OpenVDB's own log lines (it writes "WARNING: …" to std::cerr) out of the one-line
// error a bad file gets, and readInChildProcess: OpenVDB's reader can corrupt its heap on
// damaged leaf data (a flipped byte in a compressed chunk header, found by fuzzing), which
// no pre-check short of a second VDB reader can rule out, so the read is tried first in a
// forked child, where a crash becomes a one-line error instead of an abort.
#pragma once
#include <openvdb/io/File.h>

#include <functional>
#include <optional>
#include <sys/types.h>
#include <sstream>
#include <string>

namespace vdbsplat {

/// @brief Checks that @p path looks like a complete VDB file (magic, header, descriptors, grid extents).
/// @throw Error "<path>: not a VDB file …" or "<path>: truncated or corrupt VDB file (…)".
void checkVdbStructure(const std::string& path);

/// @brief Bytes of a linear map's data after its type name in OpenVDB's stream layout
/// (Transform::write: type name, then the map); 0 for other maps (a frustum: variable).
uint64_t vdbMapBytes(const std::string& mapType);

/// @brief Checks that @p path exists and is a regular file, then runs checkVdbStructure.
/// @throw Error naming @p path: no such file, not a regular file, not a VDB, truncated.
void checkVdbFile(const std::string& path);

/// @brief checkVdbFile, then opens @p file without delayed loading (so a truncated file fails here, not mid-render).
/// @throw Error naming @p path: no such file, not a regular file, not a VDB, truncated.
void openVdbFile(openvdb::io::File& file, const std::string& path);

/// @brief Runs @p read (OpenVDB reads of @p path that throw Error on failure) in a forked
/// child process first; returns when it succeeded there, so the caller can read for real.
/// @throw Error with the child's message when @p read threw there, or
/// "<path>: corrupt VDB file (OpenVDB's reader crashed on it: signal N)" when it died.
void readInChildProcess(const std::string& path, const std::function<void()>& read);

/// @brief A read in a forked child process, as readInChildProcess, that can also send one
/// number to the parent while it reads (hint(): e.g. a size estimate the parent can act on
/// meanwhile) and whose success the parent learns before the child has finished exiting.
class ChildRead {
public:
    /// @brief Forks; @p read runs in the child (stderr silenced) and may call its argument once.
    /// @throw Error when the pipe or the fork fails.
    ChildRead(const std::string& path, const std::function<void(const std::function<void(uint64_t)>&)>& read);
    ~ChildRead();  ///< waits for the child to exit
    ChildRead(const ChildRead&) = delete;
    ChildRead& operator=(const ChildRead&) = delete;
    /// @brief Waits for the child's number; none when it finished without sending one.
    std::optional<uint64_t> hint();
    /// @brief Returns once the child reported success.
    /// @throw Error as readInChildProcess.
    void succeeded();

private:
    bool receive();
    int reap();
    std::string path_, received_;
    int fd_ = -1, status_ = 0;
    pid_t pid_ = -1;
};

/// @brief While alive, what is written to std::cerr (OpenVDB's log) is held back. keep()
/// writes it out and ends the capture (call it once the read succeeded); destroyed
/// without keep() — the read threw and its Error says what went wrong — it is dropped.
/// Redirects a process-wide stream: use on the thread that loads, around the reads only.
class OpenVdbLogCapture {
public:
    OpenVdbLogCapture();
    ~OpenVdbLogCapture();
    OpenVdbLogCapture(const OpenVdbLogCapture&) = delete;
    OpenVdbLogCapture& operator=(const OpenVdbLogCapture&) = delete;
    void keep();
    /// @brief What was held back so far.
    std::string held() const { return held_.str(); }

private:
    std::ostringstream held_;
    std::streambuf* previous_ = nullptr;
};

}  // namespace vdbsplat
