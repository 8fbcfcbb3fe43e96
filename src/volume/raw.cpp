// volume/raw.cpp — raw volume conversion through zlib (see raw.h).
// Owns: a small RAII gzip reader (zlib inflate; trailing garbage refused), the per-type decoding (little-endian), the
// threshold rule, and the exact size check (plain files before reading, .gz files
// by counting the decompressed bytes, both too short and too long).
#include "volume/raw.h"

#include <zlib.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat {

namespace {

constexpr size_t kChunkBytes = size_t(4) << 20;  ///< rows are read in chunks of at most ~4 MiB

const char* typeName(RawType type) {
    switch (type) {
        case RawType::UInt8: return "uint8";
        case RawType::UInt16: return "uint16";
        case RawType::Float32: return "float32";
    }
    return "?";
}

/// Reads a plain or gzip-compressed file (several concatenated gzip members are one
/// stream, as gzip writes them); every failure is an Error naming the path. Anything after
/// the last member that is not another member — trailing garbage — is an error, so a file
/// that is not what it claims never converts silently.
class GzReader {
public:
    explicit GzReader(const std::string& path) : path_(path) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
        if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
        file_ = std::fopen(path.c_str(), "rb");
        if (!file_) throw Error(path + ": cannot open (" + std::strerror(errno) + ")");
        input_.resize(size_t(1) << 18);
        refill();
        gzip_ = strm_.avail_in >= 2 && input_[0] == 0x1f && input_[1] == 0x8b;
        if (gzip_ && inflateInit2(&strm_, 15 + 16) != Z_OK) throw Error(path + ": cannot start zlib");
    }
    ~GzReader() {
        if (gzip_) inflateEnd(&strm_);
        if (file_) std::fclose(file_);
    }
    GzReader(const GzReader&) = delete;
    GzReader& operator=(const GzReader&) = delete;

    /// True when the file is not gzip-compressed (read as is).
    bool direct() const { return !gzip_; }

    /// Reads up to @p n bytes; fewer only at the end of the data.
    size_t read(unsigned char* out, size_t n) { return gzip_ ? inflateInto(out, n) : copyInto(out, n); }

    /// Reads and counts every remaining byte (bounded buffer).
    uint64_t countRest() {
        std::vector<unsigned char> buffer(1 << 16);
        uint64_t total = 0;
        while (size_t got = read(buffer.data(), buffer.size())) {
            total += got;
            if (got < buffer.size()) break;
        }
        return total;
    }

private:
    /// Tops up the input buffer from the file (when it is empty); false at the end of the file.
    bool refill() {
        if (strm_.avail_in > 0) return true;
        const size_t got = std::fread(input_.data(), 1, input_.size(), file_);
        if (got == 0 && std::ferror(file_)) throw Error(path_ + ": cannot read (" + std::strerror(errno) + ")");
        strm_.next_in = input_.data();
        strm_.avail_in = unsigned(got);
        return got > 0;
    }

    size_t copyInto(unsigned char* out, size_t n) {
        size_t done = 0;
        while (done < n && refill()) {
            const size_t take = std::min<size_t>(n - done, strm_.avail_in);
            std::memcpy(out + done, strm_.next_in, take);
            strm_.next_in += take;
            strm_.avail_in -= unsigned(take);
            done += take;
        }
        return done;
    }

    size_t inflateInto(unsigned char* out, size_t n) {
        size_t done = 0;
        while (done < n && !finished_) {
            const bool more = refill();
            strm_.next_out = out + done;
            strm_.avail_out = unsigned(std::min<size_t>(n - done, kChunkBytes));
            const unsigned before = strm_.avail_out;
            const int rc = inflate(&strm_, Z_NO_FLUSH);
            done += before - strm_.avail_out;
            if (rc == Z_STREAM_END) {
                nextMember();
            } else if (rc == Z_DATA_ERROR || rc == Z_NEED_DICT) {
                throw Error(path_ + ": corrupt gzip data (" + (strm_.msg ? strm_.msg : "data error") + ")");
            } else if (rc == Z_MEM_ERROR) {
                throw Error(path_ + ": out of memory while decompressing");
            } else if (rc == Z_BUF_ERROR && !more) {
                throw Error(path_ + ": truncated gzip data (unexpected end of file)");
            }
        }
        return done;
    }

    /// After a member's end: another member follows (decode it), the file ends, or it is garbage.
    void nextMember() {
        if (!refill()) {
            finished_ = true;
            return;
        }
        if (strm_.next_in[0] != 0x1f || (strm_.avail_in >= 2 && strm_.next_in[1] != 0x8b))
            throw Error(path_ + ": trailing garbage after the gzip data (at compressed byte " +
                        std::to_string(consumed()) + ")");
        inflateReset(&strm_);
    }

    uint64_t consumed() const { return uint64_t(std::ftell(file_)) - strm_.avail_in; }

    std::string path_;
    std::FILE* file_ = nullptr;
    z_stream strm_{};
    std::vector<unsigned char> input_;
    bool gzip_ = false;
    bool finished_ = false;
};

std::string sizeMismatch(const std::string& path, const RawSpec& spec, uint64_t expected, const std::string& actual) {
    return path + ": size mismatch: --dims " + std::to_string(spec.dims[0]) + "," + std::to_string(spec.dims[1]) + "," +
           std::to_string(spec.dims[2]) + " of " + typeName(spec.type) + " needs " + std::to_string(expected) +
           " bytes, the file has " + actual;
}

/// Decodes voxel @p i of a little-endian row; returns the normalised value.
double decode(const unsigned char* row, size_t i, RawType type) {
    switch (type) {
        case RawType::UInt8: return row[i] / 255.0;
        case RawType::UInt16: return (unsigned(row[2 * i]) | unsigned(row[2 * i + 1]) << 8) / 65535.0;
        case RawType::Float32: {
            const unsigned char* b = row + 4 * i;
            const uint32_t bits = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
            return double(std::bit_cast<float>(bits));
        }
    }
    return 0.0;
}

/// Activates the voxels of @p rows consecutive rows starting at (0, y, z).
void addRows(const unsigned char* data, int rows, int y, int z, const RawSpec& spec,
             openvdb::FloatGrid::Accessor& acc, RawStats& stats) {
    const int nx = spec.dims[0];
    const size_t rowBytes = size_t(nx) * rawTypeSize(spec.type);
    for (int r = 0; r < rows; ++r) {
        const unsigned char* row = data + r * rowBytes;
        for (int x = 0; x < nx; ++x) {
            const double v = decode(row, size_t(x), spec.type);
            if (!std::isfinite(v)) {
                ++stats.nonFinite;
                continue;
            }
            if (v > spec.threshold) {
                acc.setValueOn(openvdb::Coord(x, y + r, z), float(v));
                ++stats.active;
            }
        }
    }
}

/// Refuses dims whose product exceeds spec.maxVoxels before anything is read: a small
/// gzip file can expand into billions of active voxels.
void checkVoxelLimit(const RawSpec& spec) {
    const uint64_t voxels = uint64_t(spec.dims[0]) * uint64_t(spec.dims[1]) * uint64_t(spec.dims[2]);
    if (voxels <= spec.maxVoxels) return;
    throw Error("--dims: " + std::to_string(spec.dims[0]) + "," + std::to_string(spec.dims[1]) + "," +
                std::to_string(spec.dims[2]) + " is " + std::to_string(voxels) + " voxels, more than the limit of " +
                std::to_string(spec.maxVoxels) + " (raise it with --max-voxels, at most " +
                std::to_string(kHardMaxRawVoxels) + ")");
}

}  // namespace

int rawTypeSize(RawType type) { return type == RawType::UInt8 ? 1 : type == RawType::UInt16 ? 2 : 4; }

RawType parseRawType(std::string_view text, const std::string& flag) {
    if (text == "uint8") return RawType::UInt8;
    if (text == "uint16") return RawType::UInt16;
    if (text == "float32") return RawType::Float32;
    throw Error(flag + ": unknown type '" + std::string(text) + "' (choose uint8, uint16 or float32)");
}

std::array<int, 3> parseDims(std::string_view text, const std::string& flag) {
    std::array<int, 3> dims{};
    size_t start = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const size_t comma = text.find(',', start);
        if ((axis < 2) != (comma != std::string_view::npos))
            throw Error(flag + ": expected X,Y,Z (three integers), got '" + std::string(text) + "'");
        const std::string_view item = text.substr(start, comma == std::string_view::npos ? text.npos : comma - start);
        dims[axis] = int(parseInt(item, flag, 1, kMaxRawDim));
        start = comma + 1;
    }
    return dims;
}

double parseUniformSpacing(std::string_view text, const std::string& flag) {
    const std::vector<double> s = parseDoubleList(text, flag, 3);
    for (double v : s)
        if (!(v > 0.0)) throw Error(flag + ": spacing must be positive, got '" + std::string(text) + "'");
    for (double v : s)
        if (v < kMinRawSpacing || v > kMaxRawSpacing)
            throw Error(flag + ": spacing '" + std::string(text) + "' is outside [1e-4, 1e6] world units per voxel " +
                        "(pick units that bring it into range, e.g. mm instead of m)");
    const double tol = 1e-6 * s[0];
    if (std::abs(s[1] - s[0]) > tol || std::abs(s[2] - s[0]) > tol)
        throw Error(flag + ": non-uniform spacing '" + std::string(text) +
                    "' is not supported (the renderer needs cubic voxels; resample the volume first)");
    return s[0];
}

openvdb::FloatGrid::Ptr convertRaw(const std::string& path, const RawSpec& spec, RawStats* statsOut) {
    for (int d : spec.dims)
        if (d < 1 || d > kMaxRawDim) throw Error(path + ": dimensions must be in [1, " + std::to_string(kMaxRawDim) + "]");
    const size_t rowBytes = size_t(spec.dims[0]) * rawTypeSize(spec.type);
    const uint64_t expected = uint64_t(rowBytes) * uint64_t(spec.dims[1]) * uint64_t(spec.dims[2]);
    checkVoxelLimit(spec);
    GzReader reader(path);
    if (reader.direct()) {
        std::error_code ec;
        const uint64_t size = std::filesystem::file_size(path, ec);
        if (!ec && size != expected) throw Error(sizeMismatch(path, spec, expected, std::to_string(size)));
    }
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(spec.spacing));
    auto acc = grid->getAccessor();
    RawStats stats;
    const int rowsPerChunk = int(std::clamp<size_t>(kChunkBytes / rowBytes, 1, size_t(spec.dims[1])));
    std::vector<unsigned char> buffer(rowBytes * rowsPerChunk);
    for (int z = 0; z < spec.dims[2]; ++z) {
        for (int y = 0; y < spec.dims[1]; y += rowsPerChunk) {
            const int rows = std::min(rowsPerChunk, spec.dims[1] - y);
            const size_t got = reader.read(buffer.data(), rows * rowBytes);
            stats.bytes += got;
            if (got < rows * rowBytes)
                throw Error(sizeMismatch(path, spec, expected, "only " + std::to_string(stats.bytes) + " (too short)"));
            addRows(buffer.data(), rows, y, z, spec, acc, stats);
        }
    }
    if (const uint64_t extra = reader.countRest())
        throw Error(sizeMismatch(path, spec, expected, std::to_string(expected + extra) + " (too long)"));
    if (statsOut) *statsOut = stats;
    return grid;
}

}  // namespace vdbsplat
