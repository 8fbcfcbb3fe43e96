// volume/vdb_check.cpp — structural pre-check of .vdb files (see vdb_check.h).
// Layout (OpenVDB io::Archive, file versions 213+): int64 magic 0x56444220, uint32 file
// version, uint32 library major, minor, char hasGridOffsets, 36-byte UUID, file metadata
// (int32 count; per item: name string, type string, uint32 size, bytes), int32 grid
// count, then per grid: name, type, instance-parent strings, int64 gridPos, blockPos,
// endPos, and the grid's bytes up to endPos. Strings are uint32 length + bytes.
// A grid's own header, at gridPos: uint32 compression flags (versions 222+), its metadata
// (the same layout as the file's), the transform's map type name, ... topology, and its
// leaf buffers from blockPos. Its metadata and map name must end before blockPos: OpenVDB
// allocates whatever lengths it finds there (gigabytes from a flipped byte) and loops over
// whatever count (minutes).
#include "volume/vdb_check.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <utility>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <openvdb/Metadata.h>
#include <tbb/global_control.h>

#include "util/error.h"
#include "volume/grid.h"
#include "volume/vdb_types.h"

namespace vdbsplat {

namespace {

constexpr int64_t kVdbMagic = 0x56444220;
/// The oldest layout read: 213 (UUID as 36 characters, root node map), from before OpenVDB
/// 1.0. Older pre-release layouts are refused: OpenVDB reads them without any check (a fuzzed
/// 41-byte file of version 0 took 135 MB and a second, half a minute under ASan).
constexpr uint32_t kFirstCheckedVersion = 213;
constexpr uint32_t kInstancingVersion = 216;     ///< grid descriptors carry an instance-parent name
constexpr uint32_t kGridCompressionVersion = 222;  ///< each grid starts with its compression flags

/// Bounds-checked little-endian reads from an ifstream of known size.
class Reader {
public:
    Reader(const std::string& path, uint64_t size) : in_(path, std::ios::binary), size_(size), path_(path) {
        if (!in_) throw Error(path + ": cannot open for reading");
    }
    template <typename T>
    T value(const char* what) {
        need(sizeof(T), what);
        T v{};
        in_.read(reinterpret_cast<char*>(&v), sizeof(T));
        pos_ += sizeof(T);
        return v;
    }
    void skip(uint64_t n, const char* what) {
        need(n, what);
        pos_ += n;
        in_.seekg(std::streamoff(pos_));
    }
    void skipString(const char* what) { skip(value<uint32_t>(what), what); }
    /// A string of at most @p maxLength bytes; longer ones are skipped and read as "".
    std::string string(const char* what, uint32_t maxLength = 64) {
        const uint32_t n = value<uint32_t>(what);
        need(n, what);
        if (n > maxLength) {
            skip(n, what);
            return "";
        }
        std::string text(n, '\0');
        in_.read(text.data(), n);
        pos_ += n;
        return text;
    }
    void seek(uint64_t to, const char* what) {
        if (to < pos_ || to > size_) corrupt(what);
        pos_ = to;
        in_.seekg(std::streamoff(pos_));
    }
    uint64_t pos() const { return pos_; }
    uint64_t size() const { return size_; }
    /// Reads past @p end (≤ size) are corrupt until the limit is lifted with limit(size()).
    void limit(uint64_t end) { end_ = std::min(end, size_); }
    [[noreturn]] void corrupt(const char* what) const {
        throw Error(path_ + ": truncated or corrupt VDB file (" + what + " at byte " + std::to_string(pos_) + " of " +
                    std::to_string(size_) + ")");
    }

private:
    void need(uint64_t n, const char* what) {
        if (pos_ > end_ || n > end_ - pos_ || !in_) corrupt(what);
    }
    std::ifstream in_;
    uint64_t size_, pos_ = 0, end_ = size_;
    std::string path_;
};

/// A metadata block (the file's or a grid's): every item within the reader's limit, each
/// fixed-size value declaring exactly the size OpenVDB reads. OpenVDB's reader consumes
/// sizeof(T) of a registered fixed-size type (TypedMetadata<T>, Metadata.h) whatever size the
/// file declares, so the check must walk the same bytes or it goes out of step with the reader
/// (a fuzzed `int64` item declaring 9 bytes made OpenVDB take a string length from the wrong
/// place: 5 GB allocated for a 5.6 KB file); fixedMetadataBytes (volume/vdb_types.h) knows them.
void skipMetadata(Reader& r, uint64_t end) {
    const int32_t count = r.value<int32_t>("metadata count");
    if (count < 0 || uint64_t(count) > (end - std::min(end, r.pos())) / 12) r.corrupt("metadata count");
    for (int32_t i = 0; i < count; ++i) {
        r.skipString("metadata name");
        const std::string type = r.string("metadata type");
        const uint32_t declared = r.value<uint32_t>("metadata value size");
        const std::optional<uint64_t> fixed = fixedMetadataBytes(type);
        if (fixed && *fixed != declared) r.corrupt("metadata value size");
        r.skip(declared, "metadata value");
    }
}

/// Bytes of a tree's value type from the grid type ("Tree_float_5_4_3"); 0 when unknown.
uint64_t valueBytes(const std::string& gridType) {
    static const std::pair<const char*, uint64_t> kTypes[] = {
        {"Tree_float_", 4}, {"Tree_double_", 8}, {"Tree_int32_", 4}, {"Tree_int64_", 8}, {"Tree_bool_", 1},
        {"Tree_vec3s_", 12}, {"Tree_vec3d_", 24}, {"Tree_vec3i_", 12}};
    for (const auto& [prefix, bytes] : kTypes)
        if (gridType.rfind(prefix, 0) == 0) return bytes;
    return 0;
}

/// The grid's header in [gridPos, blockPos): compression flags, metadata, transform, and the
/// root node's tile and child counts, each tile or child taking at least 13 bytes there
/// (a flipped high byte of a count made OpenVDB loop 3.5 billion times: a minute).
void checkGridHeader(Reader& r, uint32_t version, const std::string& gridType, uint64_t gridPos,
                     uint64_t blockPos) {
    r.seek(gridPos, "grid offset");
    r.limit(blockPos);
    if (version >= kGridCompressionVersion) r.value<uint32_t>("grid compression flags");
    skipMetadata(r, blockPos);
    if (version >= kInstancingVersion) {  // older files put the topology first
        const uint64_t map = vdbMapBytes(r.string("grid transform type"));
        const uint64_t value = valueBytes(gridType);
        if (map > 0 && value > 0) {
            r.skip(map, "grid transform");
            r.value<int32_t>("tree buffer count");
            r.skip(value, "root background value");
            const uint64_t tiles = r.value<uint32_t>("root tile count");
            const uint64_t children = r.value<uint32_t>("root child count");
            if ((tiles + children) * 13 > blockPos - r.pos()) r.corrupt("root node tile or child count");
        }
    }
    r.limit(r.size());  // the caller goes on forward, to the grid's end (≥ blockPos)
}

/// Files without grid offsets (written by io::Stream) hold each grid right after its
/// descriptor, and OpenVDB reads them in sequence. Only the first grid's start is known
/// without parsing its tree; later ones are checked where the descriptor's offsets are
/// consistent (files written by io::File with the flag cleared), otherwise refused.
void checkSequentialGrids(Reader& r, uint32_t version) {
    const int32_t grids = r.value<int32_t>("grid count");
    if (grids < 0 || uint64_t(grids) > (r.size() - r.pos()) / 32) r.corrupt("grid count");
    for (int32_t i = 0; i < grids; ++i) {
        r.skipString("grid name");
        const std::string type = r.string("grid type");
        if (version >= kInstancingVersion) r.skipString("grid instance parent");
        const int64_t gridPos = r.value<int64_t>("grid offset");
        const int64_t blockPos = r.value<int64_t>("grid data offset");
        const int64_t endPos = r.value<int64_t>("grid end offset");
        const bool consistent = gridPos == int64_t(r.pos()) && blockPos >= gridPos && endPos >= blockPos &&
                                uint64_t(endPos) <= r.size();
        if (consistent) {
            checkGridHeader(r, version, type, uint64_t(gridPos), uint64_t(blockPos));
            r.seek(uint64_t(endPos), "grid end offset");
        } else if (grids == 1) {
            checkGridHeader(r, version, type, r.pos(), r.size());
        } else {
            r.corrupt("grid without offsets in a file of several grids (not supported)");
        }
    }
}

void checkGridDescriptors(Reader& r, uint32_t version) {
    const int32_t grids = r.value<int32_t>("grid count");
    if (grids < 0 || uint64_t(grids) > (r.size() - r.pos()) / 32) r.corrupt("grid count");
    for (int32_t i = 0; i < grids; ++i) {
        r.skipString("grid name");
        const std::string type = r.string("grid type");
        if (version >= kInstancingVersion) r.skipString("grid instance parent");
        const int64_t gridPos = r.value<int64_t>("grid offset");
        const int64_t blockPos = r.value<int64_t>("grid data offset");
        const int64_t endPos = r.value<int64_t>("grid end offset");
        if (gridPos < int64_t(r.pos()) || blockPos < gridPos || endPos < blockPos || uint64_t(endPos) > r.size())
            r.corrupt("grid extends past the end of the file");
        checkGridHeader(r, version, type, uint64_t(gridPos), uint64_t(blockPos));
        r.seek(uint64_t(endPos), "grid end offset");
    }
}

}  // namespace

// math/Maps.cc: ScaleMap reads five Vec3d, ScaleTranslateMap six, TranslationMap one,
// AffineMap and UnitaryMap a Mat4d.
uint64_t vdbMapBytes(const std::string& type) {
    if (type == "UniformScaleMap" || type == "ScaleMap") return 5 * 24;
    if (type == "UniformScaleTranslateMap" || type == "ScaleTranslateMap") return 6 * 24;
    if (type == "TranslationMap") return 24;
    if (type == "AffineMap" || type == "UnitaryMap") return 128;
    return 0;
}

void checkVdbStructure(const std::string& path) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path + ": cannot read (" + ec.message() + ")");
    if (size < 8) throw Error(path + ": not a VDB file (only " + std::to_string(size) + " bytes)");
    Reader r(path, size);
    if (r.value<int64_t>("magic number") != kVdbMagic) throw Error(path + ": not a VDB file (wrong magic number)");
    const uint32_t version = r.value<uint32_t>("file version");
    if (version < kFirstCheckedVersion)
        throw Error(path + ": VDB file version " + std::to_string(version) + " is older than any OpenVDB release (" +
                    std::to_string(kFirstCheckedVersion) + " or later is read)");
    r.value<uint32_t>("library major version");
    r.value<uint32_t>("library minor version");
    const char hasOffsets = r.value<char>("grid offsets flag");
    r.skip(36, "file UUID");
    skipMetadata(r, size);
    if (hasOffsets)
        checkGridDescriptors(r, version);
    else
        checkSequentialGrids(r, version);
}

void checkVdbFile(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
    checkVdbStructure(path);  // OpenVDB does not bound its reads on truncated files
}

void openVdbFile(openvdb::io::File& file, const std::string& path) {
    checkVdbFile(path);
    initOpenVdb();  // OpenVDB's metadata, map and grid registries
    try {
        file.open(/*delayLoad=*/false);
    } catch (const std::exception& e) {
        throw Error(path + ": not a readable VDB file (" + std::string(e.what()) + ")");
    }
}

OpenVdbLogCapture::OpenVdbLogCapture() : previous_(std::cerr.rdbuf(held_.rdbuf())) {}

OpenVdbLogCapture::~OpenVdbLogCapture() {
    if (previous_) std::cerr.rdbuf(previous_);
}

void OpenVdbLogCapture::keep() {
    if (!previous_) return;
    std::cerr.rdbuf(previous_);
    previous_ = nullptr;
    std::cerr << held_.str();
}

namespace {
/// TBB is not fork-safe: a child inherits the scheduler's state but not its worker threads, nor
/// the locks they held, so a parallel_for there (OpenVDB frees a tree's leaves with one, as the
/// child's grid goes out of scope) can wait for ever. Before forking, wait for the workers to end
/// (oneTBB's documented way to fork: tbb::finalize; the next parallel call starts them again, a
/// few tens of µs). Should it not manage (called inside a parallel region), fork as before.
void waitForTbbWorkers() {
    tbb::task_scheduler_handle handle{tbb::attach{}};
    (void)tbb::finalize(handle, std::nothrow);
}
}  // namespace

// The pipe carries messages: 'H' + 8 bytes (a hint), then 'K' (success) or 'E' + text (an Error).
ChildRead::ChildRead(const std::string& path, const std::function<void(const std::function<void(uint64_t)>&)>& read)
    : path_(path) {
    int fds[2];
    if (::pipe(fds) != 0) throw Error(path + ": cannot check the file (pipe failed)");
    std::cout.flush();
    std::cerr.flush();
    waitForTbbWorkers();
    pid_ = ::fork();
    if (pid_ < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        throw Error(path + ": cannot check the file (fork failed)");
    }
    if (pid_ == 0) {  // the child: read, report, and leave without running any destructor
        ::close(fds[0]);
        // Silence the child: OpenVDB's std::cerr lines are the caller's to capture and pass on,
        // and glibc's "free(): invalid size" on a heap OpenVDB corrupted must not add a line
        // (LIBC_FATAL_STDERR_ keeps it off the terminal, the null fd 2 swallows it).
        std::ostringstream quiet;
        std::cerr.rdbuf(quiet.rdbuf());
        ::setenv("LIBC_FATAL_STDERR_", "1", 1);
        if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, 2);
        const auto send = [&](const std::string& bytes) {
            for (size_t done = 0; done < bytes.size();) {
                const ssize_t n = ::write(fds[1], bytes.data() + done, bytes.size() - done);
                if (n < 0 && errno == EINTR) continue;
                if (n <= 0) break;
                done += size_t(n);
            }
        };
        bool hinted = false;
        const auto hint = [&](uint64_t n) {
            if (hinted) return;
            hinted = true;
            std::string m(9, 'H');
            std::memcpy(m.data() + 1, &n, 8);
            send(m);
        };
        std::string message;
        try {
            read(hint);
        } catch (const Error& e) {
            message = e.what();
        } catch (const std::exception& e) {  // a library's exception: name the file
            message = path + ": corrupt VDB file (" + std::string(e.what()) + ")";
        } catch (...) {
            message = path + ": corrupt VDB file";
        }
        send(message.empty() ? "K" : "E" + message.substr(0, 4096));
        ::_exit(message.empty() ? 0 : 1);
    }
    ::close(fds[1]);
    fd_ = fds[0];
}

bool ChildRead::receive() {
    char buffer[4096];
    for (;;) {
        const ssize_t n = ::read(fd_, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        if (received_.size() < 8192) received_.append(buffer, size_t(n));
        return true;
    }
}

std::optional<uint64_t> ChildRead::hint() {
    while (received_.empty() || (received_[0] == 'H' && received_.size() < 9))
        if (!receive()) break;
    if (received_.size() < 9 || received_[0] != 'H') return std::nullopt;
    uint64_t n = 0;
    std::memcpy(&n, received_.data() + 1, 8);
    received_.erase(0, 9);
    return n;
}

void ChildRead::succeeded() {
    for (;;) {
        if (received_.size() >= 9 && received_[0] == 'H') received_.erase(0, 9);  // a hint not asked for
        if (received_ == "K") return;  // the child may still be exiting: the destructor reaps it
        if (!receive()) break;
    }
    const int status = reap();
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0 && received_.size() > 1 && received_[0] == 'E')
        throw Error(received_.substr(1));
    const int signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    throw Error(path_ + ": corrupt VDB file (OpenVDB's reader crashed on it: " +
                (signal ? "signal " + std::to_string(signal) : "exit " + std::to_string(WEXITSTATUS(status))) + ")");
}

int ChildRead::reap() {
    if (fd_ >= 0) {
        ::close(fd_);
        fd_ = -1;
    }
    if (pid_ > 0) {
        while (::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
        }
        pid_ = -1;
    }
    return status_;
}

ChildRead::~ChildRead() { reap(); }

void readInChildProcess(const std::string& path, const std::function<void()>& read) {
    ChildRead child(path, [&](const std::function<void(uint64_t)>&) { read(); });
    child.succeeded();
}

}  // namespace vdbsplat
