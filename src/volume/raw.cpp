// volume/raw.cpp — raw volume conversion through zlib (see raw.h).
// Owns: a small RAII gzip reader (zlib inflate; trailing garbage refused), the per-type decoding (either byte
// order), the normalisation and threshold rule (DensityBuilder, shared by every convert format), and the
// exact size check (plain files before reading, .gz files by counting the decompressed bytes, both too
// short and too long).
#include "volume/raw.h"

#include <zlib.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat {

namespace {

constexpr size_t kChunkBytes = size_t(4) << 20;  ///< rows are read in chunks of at most ~4 MiB
constexpr uint64_t kMaxCountedExtra = uint64_t(1) << 26;  ///< bytes past the voxels counted for the error

/// Reads a plain or gzip-compressed file (several concatenated gzip members are one
/// stream, as gzip writes them); every failure is an Error naming the path. Anything after
/// the last member that is not another member — trailing garbage — is an error, so a file
/// that is not what it claims never converts silently.
class GzReader {
public:
    /// Opens @p path at byte @p offset; @p encoding Detect: gzip iff the data starts with its magic.
    GzReader(const std::string& path, const std::string& label, uint64_t offset, VoxelSource::Encoding encoding)
        : path_(label) {
        file_ = std::fopen(path.c_str(), "rb");
        if (!file_) throw Error(label + ": cannot open (" + std::strerror(errno) + ")");
        if (offset > uint64_t(std::numeric_limits<long>::max()) || std::fseek(file_, long(offset), SEEK_SET) != 0)
            throw Error(label + ": cannot seek to byte " + std::to_string(offset));
        input_.resize(size_t(1) << 18);
        refill();
        const bool magic = strm_.avail_in >= 2 && input_[0] == 0x1f && input_[1] == 0x8b;
        gzip_ = encoding == VoxelSource::Encoding::Gzip || (encoding == VoxelSource::Encoding::Detect && magic);
        if (gzip_ && inflateInit2(&strm_, 15 + 16) != Z_OK) throw Error(label + ": cannot start zlib");
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

    /// Reads and counts the remaining bytes, stopping past @p limit (a gzip bomb after the
    /// voxels would otherwise be inflated to its end just to count it).
    uint64_t countRest(uint64_t limit) {
        std::vector<unsigned char> buffer(1 << 16);
        uint64_t total = 0;
        while (size_t got = read(buffer.data(), buffer.size())) {
            total += got;
            if (got < buffer.size() || total > limit) break;
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

std::string labelOf(const VoxelSource& source) { return source.label.empty() ? source.path : source.label; }

std::string sizeMismatch(const VoxelSource& source, const VoxelLayout& layout, uint64_t expected,
                         const std::string& actual) {
    const char sep = source.sizeField == "--dims" ? ',' : ' ';
    return labelOf(source) + ": size mismatch: " + source.sizeField + " " + std::to_string(layout.dims[0]) + sep +
           std::to_string(layout.dims[1]) + sep + std::to_string(layout.dims[2]) + " of " + rawTypeName(layout.type) +
           " needs " + std::to_string(expected) + " bytes, the " + (source.offset || source.skip ? "data" : "file") +
           " has " + actual;
}

/// Reads @p n bytes of @p p as an unsigned integer in the given byte order.
uint64_t loadBits(const unsigned char* p, int n, bool bigEndian) {
    uint64_t v = 0;
    for (int k = 0; k < n; ++k) v |= uint64_t(p[bigEndian ? n - 1 - k : k]) << (8 * k);
    return v;
}

/// Decodes one voxel; returns its normalised value (NaN for what float32 cannot hold).
double decode(const unsigned char* p, RawType type, bool bigEndian) {
    switch (type) {
        case RawType::UInt8: return p[0] / 255.0;
        case RawType::Int16: return int16_t(uint16_t(loadBits(p, 2, bigEndian))) / 32767.0;
        case RawType::UInt16: return double(loadBits(p, 2, bigEndian)) / 65535.0;
        case RawType::Float32: return double(std::bit_cast<float>(uint32_t(loadBits(p, 4, bigEndian))));
        case RawType::Float64: {
            const double v = std::bit_cast<double>(loadBits(p, 8, bigEndian));
            return std::abs(v) <= double(std::numeric_limits<float>::max()) ? v : NAN;
        }
    }
    return 0.0;
}

/// Reads the voxels of @p source into @p builder (the size already checked for plain files).
void streamInto(GzReader& reader, const VoxelSource& source, const VoxelLayout& layout, DensityBuilder& builder) {
    const uint64_t expected = builder.expectedBytes();
    std::vector<unsigned char> buffer(std::min<uint64_t>(kChunkBytes, std::max<uint64_t>(expected, source.skip) + 1));
    for (uint64_t skipped = 0; skipped < source.skip;) {
        const size_t got = reader.read(buffer.data(), size_t(std::min<uint64_t>(buffer.size(), source.skip - skipped)));
        if (got == 0) throw Error(sizeMismatch(source, layout, expected, "fewer than its byte skip of " +
                                                                             std::to_string(source.skip) + " bytes"));
        skipped += got;
    }
    while (builder.bytes() < expected) {
        const size_t want = size_t(std::min<uint64_t>(buffer.size(), expected - builder.bytes()));
        const size_t got = reader.read(buffer.data(), want);
        builder.addBytes(buffer.data(), got);
        if (got < want)
            throw Error(sizeMismatch(source, layout, expected, "only " + std::to_string(builder.bytes()) + " (too short)"));
    }
    if (const uint64_t extra = reader.countRest(kMaxCountedExtra))
        throw Error(sizeMismatch(source, layout, expected,
                                 (extra > kMaxCountedExtra ? "more than " : "") + std::to_string(expected + extra) + " (too long)"));
}

/// The file offset of plain data, checking the file's size against the layout before reading.
uint64_t plainOffset(const VoxelSource& source, const VoxelLayout& layout, uint64_t expected) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(source.path, ec);
    if (ec) return source.offset + source.skip;
    if (source.atEnd) {
        if (size < expected) throw Error(sizeMismatch(source, layout, expected, std::to_string(size) + " (too short)"));
        return size - expected;
    }
    const uint64_t start = source.offset + source.skip;
    const uint64_t have = size >= start ? size - start : 0;
    if (have != expected) throw Error(sizeMismatch(source, layout, expected, std::to_string(have)));
    return start;
}

}  // namespace

int rawTypeSize(RawType type) {
    switch (type) {
        case RawType::UInt8: return 1;
        case RawType::Int16:
        case RawType::UInt16: return 2;
        case RawType::Float32: return 4;
        case RawType::Float64: return 8;
    }
    return 1;
}

const char* rawTypeName(RawType type) {
    switch (type) {
        case RawType::UInt8: return "uint8";
        case RawType::Int16: return "int16";
        case RawType::UInt16: return "uint16";
        case RawType::Float32: return "float32";
        case RawType::Float64: return "float64";
    }
    return "?";
}

RawType parseRawType(std::string_view text, const std::string& flag) {
    for (RawType t : {RawType::UInt8, RawType::Int16, RawType::UInt16, RawType::Float32, RawType::Float64})
        if (text == rawTypeName(t)) return t;
    throw Error(flag + ": unknown type '" + std::string(text) + "' (choose uint8, int16, uint16, float32 or float64)");
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

std::array<double, 3> parseSpacing(std::string_view text, const std::string& flag) {
    const std::vector<double> s = parseDoubleList(text, flag, 3);
    for (double v : s)
        if (!(v > 0.0)) throw Error(flag + ": spacing must be positive, got '" + std::string(text) + "'");
    for (double v : s)
        if (v < kMinRawSpacing || v > kMaxRawSpacing)
            throw Error(flag + ": spacing '" + std::string(text) + "' is outside [1e-4, 1e6] world units per voxel " +
                        "(pick units that bring it into range, e.g. mm instead of m)");
    return {s[0], s[1], s[2]};
}

openvdb::math::Transform::Ptr spacingTransform(const std::array<double, 3>& s) {
    if (s[0] == s[1] && s[0] == s[2]) return openvdb::math::Transform::createLinearTransform(s[0]);
    return openvdb::math::Transform::createLinearTransform(
        openvdb::Mat4d(s[0], 0.0, 0.0, 0.0, 0.0, s[1], 0.0, 0.0, 0.0, 0.0, s[2], 0.0, 0.0, 0.0, 0.0, 1.0));
}

uint64_t voxelCount(const std::array<int, 3>& dims) {
    return uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
}

void checkVoxelLimit(const std::array<int, 3>& dims, uint64_t maxVoxels, const std::string& field) {
    const uint64_t voxels = voxelCount(dims);
    if (voxels <= maxVoxels) return;
    throw Error(field + ": " + std::to_string(dims[0]) + "," + std::to_string(dims[1]) + "," + std::to_string(dims[2]) +
                " is " + std::to_string(voxels) + " voxels, more than the limit of " + std::to_string(maxVoxels) +
                " (raise it with --max-voxels, at most " + std::to_string(kHardMaxRawVoxels) + ")");
}

DensityBuilder::DensityBuilder(const VoxelLayout& layout, double threshold, openvdb::math::Transform::Ptr transform)
    : layout_(layout),
      threshold_(threshold),
      grid_(openvdb::FloatGrid::create(0.0f)),
      acc_(grid_->getAccessor()),
      total_(voxelCount(layout.dims)) {
    grid_->setName("density");
    grid_->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid_->setTransform(transform);
    stats_.voxels = total_;
}

void DensityBuilder::addVoxel(const unsigned char* bytes) {
    const double v = decode(bytes, layout_.type, layout_.bigEndian);
    if (!std::isfinite(v)) {
        ++stats_.nonFinite;
    } else if (v > threshold_) {
        acc_.setValueOn(at_, float(v));
        ++stats_.active;
    }
    ++next_;
    if (++at_[0] < layout_.dims[0]) return;
    at_[0] = 0;
    if (++at_[1] < layout_.dims[1]) return;
    at_[1] = 0;
    ++at_[2];
}

void DensityBuilder::addBytes(const unsigned char* data, size_t n) {
    const int size = rawTypeSize(layout_.type);
    bytes_ += n;
    stats_.bytes = bytes_;
    while (n > 0 && pendingBytes_ > 0) {  // complete a voxel split across calls
        pending_[pendingBytes_++] = *data++;
        --n;
        if (pendingBytes_ == size) {
            pendingBytes_ = 0;
            if (next_ < total_) addVoxel(pending_);
        }
    }
    for (; n >= size_t(size) && next_ < total_; n -= size, data += size) addVoxel(data);
    if (next_ < total_)
        for (; n > 0; --n) pending_[pendingBytes_++] = *data++;
}

openvdb::FloatGrid::Ptr readVoxels(const VoxelSource& source, const VoxelLayout& layout, double threshold,
                                   openvdb::math::Transform::Ptr transform, RawStats* stats) {
    std::error_code ec;
    if (!std::filesystem::exists(source.path, ec)) throw Error(labelOf(source) + ": no such file");
    if (!std::filesystem::is_regular_file(source.path, ec)) throw Error(labelOf(source) + ": not a regular file");
    DensityBuilder builder(layout, threshold, std::move(transform));
    const uint64_t expected = builder.expectedBytes();
    VoxelSource where = source;
    if (source.encoding != VoxelSource::Encoding::Gzip) {
        GzReader probe(source.path, labelOf(source), source.offset, source.encoding);
        if (probe.direct()) {
            where.offset = plainOffset(source, layout, expected);
            where.skip = 0;
            where.encoding = VoxelSource::Encoding::Raw;
        }
    }
    GzReader reader(where.path, labelOf(where), where.offset, where.encoding);
    streamInto(reader, where, layout, builder);
    if (stats) *stats = builder.stats();
    return builder.grid();
}

openvdb::FloatGrid::Ptr convertRaw(const std::string& path, const RawSpec& spec, RawStats* statsOut) {
    for (int d : spec.dims)
        if (d < 1 || d > kMaxRawDim) throw Error(path + ": dimensions must be in [1, " + std::to_string(kMaxRawDim) + "]");
    checkVoxelLimit(spec.dims, spec.maxVoxels, "--dims");
    VoxelSource source;
    source.path = path;
    const VoxelLayout layout{spec.dims, spec.type, false};
    return readVoxels(source, layout, spec.threshold, spacingTransform(spec.spacing),
                      statsOut);
}

}  // namespace vdbsplat
