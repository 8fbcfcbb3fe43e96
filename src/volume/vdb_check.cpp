// volume/vdb_check.cpp — structural pre-check of .vdb files (see vdb_check.h).
// Layout (OpenVDB io::Archive, file versions 213+): int64 magic 0x56444220, uint32 file
// version, uint32 library major, minor, char hasGridOffsets, 36-byte UUID, file metadata
// (int32 count; per item: name string, type string, uint32 size, bytes), int32 grid
// count, then per grid: name, type, instance-parent strings, int64 gridPos, blockPos,
// endPos, and the grid's bytes up to endPos. Strings are uint32 length + bytes.
#include "volume/vdb_check.h"

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace vdbsplat {

namespace {

constexpr int64_t kVdbMagic = 0x56444220;
constexpr uint32_t kFirstCheckedVersion = 213;  ///< UUID as 36 characters; older files are left to OpenVDB
constexpr uint32_t kInstancingVersion = 216;     ///< grid descriptors carry an instance-parent name

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
    void seek(uint64_t to, const char* what) {
        if (to < pos_ || to > size_) corrupt(what);
        pos_ = to;
        in_.seekg(std::streamoff(pos_));
    }
    uint64_t pos() const { return pos_; }
    uint64_t size() const { return size_; }
    [[noreturn]] void corrupt(const char* what) const {
        throw Error(path_ + ": truncated or corrupt VDB file (" + what + " at byte " + std::to_string(pos_) + " of " +
                    std::to_string(size_) + ")");
    }

private:
    void need(uint64_t n, const char* what) {
        if (n > size_ - pos_ || !in_) corrupt(what);
    }
    std::ifstream in_;
    uint64_t size_, pos_ = 0;
    std::string path_;
};

void skipFileMetadata(Reader& r) {
    const int32_t count = r.value<int32_t>("file metadata count");
    if (count < 0 || uint64_t(count) > (r.size() - r.pos()) / 12) r.corrupt("file metadata count");
    for (int32_t i = 0; i < count; ++i) {
        r.skipString("metadata name");
        r.skipString("metadata type");
        r.skipString("metadata value");  // uint32 size + bytes, like a string
    }
}

void checkGridDescriptors(Reader& r, uint32_t version) {
    const int32_t grids = r.value<int32_t>("grid count");
    if (grids < 0 || uint64_t(grids) > (r.size() - r.pos()) / 32) r.corrupt("grid count");
    for (int32_t i = 0; i < grids; ++i) {
        r.skipString("grid name");
        r.skipString("grid type");
        if (version >= kInstancingVersion) r.skipString("grid instance parent");
        const int64_t gridPos = r.value<int64_t>("grid offset");
        const int64_t blockPos = r.value<int64_t>("grid data offset");
        const int64_t endPos = r.value<int64_t>("grid end offset");
        if (gridPos < int64_t(r.pos()) || blockPos < gridPos || endPos < blockPos || uint64_t(endPos) > r.size())
            r.corrupt("grid extends past the end of the file");
        r.seek(uint64_t(endPos), "grid end offset");
    }
}

}  // namespace

void checkVdbStructure(const std::string& path) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path + ": cannot read (" + ec.message() + ")");
    if (size < 8) throw Error(path + ": not a VDB file (only " + std::to_string(size) + " bytes)");
    Reader r(path, size);
    if (r.value<int64_t>("magic number") != kVdbMagic) throw Error(path + ": not a VDB file (wrong magic number)");
    const uint32_t version = r.value<uint32_t>("file version");
    if (version < kFirstCheckedVersion) return;  // pre-2012 layout: left to OpenVDB
    r.value<uint32_t>("library major version");
    r.value<uint32_t>("library minor version");
    const char hasOffsets = r.value<char>("grid offsets flag");
    r.skip(36, "file UUID");
    skipFileMetadata(r);
    if (hasOffsets) checkGridDescriptors(r, version);
}

}  // namespace vdbsplat
