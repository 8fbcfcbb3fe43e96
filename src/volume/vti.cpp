// volume/vti.cpp — the VTK XML ImageData reader (see vti.h), following VTK's XML file formats
// (VTKFile / ImageData / Piece / PointData / DataArray; AppendedData after a `_` marker).
// Owns: finding the XML part (the raw appended block is never handed to the XML parser), the
// byte sources a DataArray is read from (memory, file, streaming base64 over either), the
// header and block decoding (uncompressed: one byte count; zlib: block count, block size, last
// block size, compressed sizes), and the bounds: every size is checked against WholeExtent and
// against the bytes that can still come before anything is allocated from it.
#include "volume/vti.h"

#include <pugixml.hpp>
#include <zlib.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "util/error.h"
#include "util/parse.h"
#include "volume/index_map.h"

namespace vdbsplat {

namespace {

constexpr size_t kChunk = size_t(1) << 16;

// --- Byte sources --------------------------------------------------------------------------

/// Bytes read in order; available() is an upper bound of what can still come.
class ByteSource {
public:
    virtual ~ByteSource() = default;
    virtual size_t read(unsigned char* out, size_t n) = 0;
    virtual uint64_t available() const = 0;
};

class MemorySource : public ByteSource {
public:
    explicit MemorySource(std::string_view data) : data_(data) {}
    size_t read(unsigned char* out, size_t n) override {
        const size_t take = std::min(n, data_.size() - pos_);
        std::memcpy(out, data_.data() + pos_, take);
        pos_ += take;
        return take;
    }
    uint64_t available() const override { return data_.size() - pos_; }

private:
    std::string_view data_;
    size_t pos_ = 0;
};

class FileSource : public ByteSource {
public:
    FileSource(const std::string& path, uint64_t offset, const std::string& what) : what_(what) {
        std::error_code ec;
        size_ = std::filesystem::file_size(path, ec);
        if (ec) throw Error(path + ": cannot read its size");
        if (offset > size_) throw Error(what + ": offset " + std::to_string(offset) + " is past the end of the file");
        file_ = std::fopen(path.c_str(), "rb");
        if (!file_) throw Error(path + ": cannot open");
        if (std::fseek(file_, long(offset), SEEK_SET) != 0) {
            std::fclose(file_);
            throw Error(what + ": cannot seek to byte " + std::to_string(offset));
        }
        pos_ = offset;
    }
    ~FileSource() override { std::fclose(file_); }
    FileSource(const FileSource&) = delete;
    FileSource& operator=(const FileSource&) = delete;
    size_t read(unsigned char* out, size_t n) override {
        const size_t got = std::fread(out, 1, n, file_);
        if (got < n && std::ferror(file_)) throw Error(what_ + ": cannot read (" + std::strerror(errno) + ")");
        pos_ += got;
        return got;
    }
    uint64_t available() const override { return size_ > pos_ ? size_ - pos_ : 0; }

private:
    std::string what_;
    std::FILE* file_ = nullptr;
    uint64_t size_ = 0, pos_ = 0;
};

/// Decodes base64 from @p chars, quantum by quantum (VTK encodes a header and the data after
/// it separately, so padding may end a quantum in the middle); whitespace is skipped, '<' or
/// the end of the characters ends the data.
class Base64Source : public ByteSource {
public:
    Base64Source(ByteSource& chars, const std::string& what) : chars_(chars), what_(what) {}
    size_t read(unsigned char* out, size_t n) override {
        size_t done = 0;
        while (done < n) {
            if (pos_ == have_ && !decodeQuantum()) break;
            const size_t take = std::min<size_t>(n - done, have_ - pos_);
            std::memcpy(out + done, bytes_ + pos_, take);
            pos_ += take;
            done += take;
        }
        return done;
    }
    uint64_t available() const override { return (chars_.available() + (end_ - at_)) / 4 * 3 + 3 + (have_ - pos_); }
    /// True when only whitespace (or the end) is left.
    bool exhausted() {
        int c;
        while ((c = nextChar()) == ' ' || c == '\n' || c == '\r' || c == '\t') {}
        return c < 0 || c == '<';
    }

private:
    int nextChar() {
        if (at_ == end_) {
            end_ = chars_.read(buffer_, sizeof buffer_);
            at_ = 0;
            if (end_ == 0) return -1;
        }
        return buffer_[at_++];
    }
    static int sextet(int c) {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        if (c == '+') return 62;
        if (c == '/') return 63;
        return c == '=' ? 64 : -1;
    }
    bool decodeQuantum() {
        int q[4], n = 0;
        while (n < 4) {
            const int c = ended_ ? -1 : nextChar();
            if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
            if (c < 0 || c == '<') {
                ended_ = true;
                if (n == 0) return false;
                throw Error(what_ + ": base64 data ends inside a 4-character group");
            }
            q[n] = sextet(c);
            if (q[n] < 0) throw Error(what_ + ": invalid base64 character (code " + std::to_string(c) + ")");
            ++n;
        }
        if (q[0] == 64 || q[1] == 64 || (q[2] == 64 && q[3] != 64)) throw Error(what_ + ": misplaced base64 padding");
        const uint32_t v = uint32_t(q[0]) << 18 | uint32_t(q[1]) << 12 | uint32_t(q[2] & 63) << 6 | uint32_t(q[3] & 63);
        bytes_[0] = (unsigned char)(v >> 16), bytes_[1] = (unsigned char)(v >> 8), bytes_[2] = (unsigned char)v;
        have_ = q[2] == 64 ? 1 : q[3] == 64 ? 2 : 3;
        pos_ = 0;
        return true;
    }

    ByteSource& chars_;
    std::string what_;
    unsigned char buffer_[kChunk];
    size_t at_ = 0, end_ = 0;
    unsigned char bytes_[3] = {};
    size_t have_ = 0, pos_ = 0;
    bool ended_ = false;
};

// --- File-level description ----------------------------------------------------------------

/// What the VTKFile element and the chosen DataArray say about how data is stored.
struct Encoding {
    bool bigEndian = false;
    int headerBytes = 4;  ///< UInt32 or UInt64 header integers
    bool zlib = false;
};

/// The XML text (with the appended block cut off) and where the appended data starts.
struct XmlPart {
    std::string text;
    bool appended = false;
    uint64_t appendedStart = 0;  ///< file offset of the byte after '_'
};

/// Reads the file up to its <AppendedData> element (or whole, when it has none).
XmlPart readXmlPart(const std::string& path) {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) throw Error(path + ": cannot open (" + std::strerror(errno) + ")");
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> guard(file, std::fclose);
    XmlPart out;
    std::vector<char> chunk(size_t(1) << 16);
    size_t found = std::string::npos;
    while (found == std::string::npos) {
        const size_t got = std::fread(chunk.data(), 1, chunk.size(), file);
        if (got == 0) break;
        const size_t from = out.text.size() > 16 ? out.text.size() - 16 : 0;
        out.text.append(chunk.data(), got);
        found = out.text.find("<AppendedData", from);
        if (out.text.size() > kMaxVtiXmlBytes)
            throw Error(path + ": the XML part is larger than " + std::to_string(kMaxVtiXmlBytes) + " bytes");
    }
    if (std::ferror(file)) throw Error(path + ": cannot read");
    if (found == std::string::npos) return out;
    if (out.text.size() - found < 4096) {  // the tag and its `_` marker are within reach
        const size_t got = std::fread(chunk.data(), 1, 4096, file);
        out.text.append(chunk.data(), got);
    }
    const size_t gt = out.text.find('>', found);
    if (gt == std::string::npos || gt - found > 1024) throw Error(path + ": AppendedData: the start tag does not end");
    size_t mark = gt + 1;
    while (mark < out.text.size() && std::strchr(" \t\r\n", out.text[mark]) && out.text[mark]) ++mark;
    if (mark >= out.text.size() || out.text[mark] != '_')
        throw Error(path + ": AppendedData: the '_' marker before the data is missing");
    out.appended = true;
    out.appendedStart = mark + 1;
    out.text.resize(gt + 1);
    out.text += "</AppendedData></VTKFile>";
    return out;
}

std::string attr(const pugi::xml_node& node, const char* name) { return node.attribute(name).as_string(); }

std::vector<double> numbers(const std::string& text, size_t count, const std::string& what) {
    std::istringstream in(text);
    std::vector<double> out;
    for (std::string w; in >> w && out.size() <= count;) out.push_back(parseDouble(w, what));
    if (out.size() != count)
        throw Error(what + ": expected " + std::to_string(count) + " numbers, got '" + printable(text) + "'");
    return out;
}

RawType arrayType(const std::string& name, const std::string& what) {
    if (name == "UInt8") return RawType::UInt8;
    if (name == "Int16") return RawType::Int16;
    if (name == "UInt16") return RawType::UInt16;
    if (name == "Float32") return RawType::Float32;
    if (name == "Float64") return RawType::Float64;
    throw Error(what + ": unsupported type '" + printable(name) + "' (supported: UInt8, Int16, UInt16, Float32, Float64)");
}

// --- Data decoding -------------------------------------------------------------------------

uint64_t readHeaderInt(ByteSource& in, const Encoding& enc, const std::string& what) {
    unsigned char b[8];
    if (in.read(b, size_t(enc.headerBytes)) != size_t(enc.headerBytes))
        throw Error(what + ": data ends inside its header");
    uint64_t v = 0;
    for (int k = 0; k < enc.headerBytes; ++k) v |= uint64_t(b[enc.bigEndian ? enc.headerBytes - 1 - k : k]) << (8 * k);
    return v;
}

void copyInto(ByteSource& in, uint64_t n, DensityBuilder& builder, const std::string& what) {
    std::vector<unsigned char> buffer(size_t(std::min<uint64_t>(n, kChunk)));
    for (uint64_t left = n; left > 0;) {
        const size_t got = in.read(buffer.data(), size_t(std::min<uint64_t>(left, buffer.size())));
        if (got == 0)
            throw Error(what + ": data is truncated (" + std::to_string(n - left) + " of " + std::to_string(n) + " bytes)");
        builder.addBytes(buffer.data(), got);
        left -= got;
    }
}

/// Inflates one zlib block of @p compressed bytes that must give exactly @p size bytes.
void inflateBlock(ByteSource& in, uint64_t compressed, uint64_t size, DensityBuilder& builder, const std::string& what) {
    z_stream zs{};
    if (inflateInit(&zs) != Z_OK) throw Error(what + ": cannot start zlib");
    std::unique_ptr<z_stream, int (*)(z_stream*)> guard(&zs, inflateEnd);
    std::vector<unsigned char> input(kChunk), output(kChunk);
    uint64_t left = compressed, produced = 0;
    for (int rc = Z_OK; rc != Z_STREAM_END;) {
        if (zs.avail_in == 0 && left > 0) {
            const size_t got = in.read(input.data(), size_t(std::min<uint64_t>(left, input.size())));
            if (got == 0) throw Error(what + ": compressed data is truncated");
            left -= got;
            zs.next_in = input.data();
            zs.avail_in = unsigned(got);
        }
        zs.next_out = output.data();
        zs.avail_out = unsigned(output.size());
        rc = inflate(&zs, Z_NO_FLUSH);
        const size_t got = output.size() - zs.avail_out;
        produced += got;
        if (produced > size)
            throw Error(what + ": inflates to more than the " + std::to_string(size) + " bytes its header gives");
        builder.addBytes(output.data(), got);
        if (rc == Z_NEED_DICT || rc == Z_DATA_ERROR || rc == Z_MEM_ERROR)
            throw Error(what + ": corrupt zlib data (" + (zs.msg ? zs.msg : "data error") + ")");
        if (rc == Z_BUF_ERROR && zs.avail_in == 0 && left == 0)
            throw Error(what + ": the zlib stream is longer than its " + std::to_string(compressed) + " compressed bytes");
    }
    if (produced != size)
        throw Error(what + ": inflates to " + std::to_string(produced) + " bytes, its header gives " + std::to_string(size));
    if (zs.avail_in > 0 || left > 0)
        throw Error(what + ": the zlib stream ends before its " + std::to_string(compressed) + " compressed bytes");
}

void readCompressed(ByteSource& in, const Encoding& enc, DensityBuilder& builder, const std::string& what) {
    const uint64_t expected = builder.expectedBytes();
    const uint64_t blocks = readHeaderInt(in, enc, what);
    const uint64_t blockSize = readHeaderInt(in, enc, what);
    const uint64_t lastSize = readHeaderInt(in, enc, what);
    // VTK writes its nominal block size (32768) even when the one block is smaller; the
    // sizes actually inflated (lastSize, or blockSize for full blocks) are ≤ expected below.
    if (blocks == 0 || blockSize == 0 || lastSize > blockSize || blocks - 1 > expected / blockSize)
        throw Error(what + ": compression header (" + std::to_string(blocks) + " blocks of " + std::to_string(blockSize) +
                    " bytes, last " + std::to_string(lastSize) + ") does not fit the " + std::to_string(expected) +
                    " bytes WholeExtent needs");
    const uint64_t total = (blocks - 1) * blockSize + (lastSize ? lastSize : blockSize);
    if (total != expected)
        throw Error(what + ": compression header gives " + std::to_string(total) + " bytes, WholeExtent needs " +
                    std::to_string(expected));
    if (blocks > in.available() / uint64_t(enc.headerBytes))
        throw Error(what + ": compression header lists " + std::to_string(blocks) + " blocks, more than the data holds");
    std::vector<uint64_t> sizes(blocks);
    for (uint64_t& s : sizes) s = readHeaderInt(in, enc, what);
    for (uint64_t b = 0; b < blocks; ++b) {
        const uint64_t size = b + 1 == blocks && lastSize ? lastSize : blockSize;
        const std::string block = what + ": zlib block " + std::to_string(b);
        if (sizes[b] > compressBound(uLong(size)) || sizes[b] > in.available())
            throw Error(block + ": compressed size " + std::to_string(sizes[b]) + " is more than zlib makes of " +
                        std::to_string(size) + " bytes or than the data holds");
        inflateBlock(in, sizes[b], size, builder, block);
    }
}

void readBinary(ByteSource& in, const Encoding& enc, DensityBuilder& builder, const std::string& what) {
    if (enc.zlib) return readCompressed(in, enc, builder, what);
    const uint64_t n = readHeaderInt(in, enc, what);
    if (n != builder.expectedBytes())
        throw Error(what + ": holds " + std::to_string(n) + " bytes, WholeExtent needs " +
                    std::to_string(builder.expectedBytes()));
    copyInto(in, n, builder, what);
}

/// Writes @p v as @p type in little-endian order (what DensityBuilder reads back).
void putValue(double v, RawType type, unsigned char* out) {
    uint64_t bits = 0;
    switch (type) {
        case RawType::UInt8: bits = uint64_t(v); break;
        case RawType::Int16: bits = uint16_t(int16_t(v)); break;
        case RawType::UInt16: bits = uint16_t(v); break;
        case RawType::Float32: bits = std::bit_cast<uint32_t>(float(v)); break;
        case RawType::Float64: bits = std::bit_cast<uint64_t>(v); break;
    }
    for (int k = 0; k < rawTypeSize(type); ++k) out[k] = (unsigned char)(bits >> (8 * k));
}

/// One ascii value, range-checked for its type.
double asciiValue(std::string_view w, RawType type, const std::string& what) {
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (ec != std::errc() || ptr != w.data() + w.size())
        throw Error(what + ": '" + printable(w) + "' is not a number");
    const bool integer = type == RawType::UInt8 || type == RawType::Int16 || type == RawType::UInt16;
    const double lo = type == RawType::Int16 ? -32768.0 : 0.0;
    const double hi = type == RawType::UInt8 ? 255.0 : type == RawType::Int16 ? 32767.0 : 65535.0;
    if (integer && !(v == std::floor(v) && v >= lo && v <= hi))
        throw Error(what + ": '" + printable(w) + "' is not a " + rawTypeName(type) + " value");
    if (type == RawType::Float32 && std::isfinite(v) && std::abs(v) > double(std::numeric_limits<float>::max()))
        throw Error(what + ": '" + printable(w) + "' is beyond float32's range");
    return v;
}

void readAscii(std::string_view text, RawType type, DensityBuilder& builder, const std::string& what) {
    const uint64_t voxels = builder.expectedBytes() / uint64_t(rawTypeSize(type));
    uint64_t count = 0;
    unsigned char bytes[8];
    for (size_t i = 0; i < text.size();) {
        while (i < text.size() && std::strchr(" \t\r\n", text[i]) && text[i]) ++i;
        const size_t start = i;
        while (i < text.size() && !std::strchr(" \t\r\n", text[i])) ++i;
        if (start == i) break;
        if (++count > voxels) throw Error(what + ": more than the " + std::to_string(voxels) + " values WholeExtent needs");
        putValue(asciiValue(text.substr(start, i - start), type, what), type, bytes);
        builder.addBytes(bytes, size_t(rawTypeSize(type)));
    }
    if (count != voxels)
        throw Error(what + ": holds " + std::to_string(count) + " values, WholeExtent needs " + std::to_string(voxels));
}

// --- The document --------------------------------------------------------------------------

class VtiReader {
public:
    VtiReader(const std::string& path, const ConvertOptions& options) : path_(path), options_(options) {}

    openvdb::FloatGrid::Ptr read(RawStats* stats) {
        xml_ = readXmlPart(path_);
        const pugi::xml_parse_result ok = doc_.load_buffer(xml_.text.data(), xml_.text.size());
        if (!ok) throw Error(path_ + ": malformed XML at byte " + std::to_string(ok.offset) + " (" + ok.description() + ")");
        const pugi::xml_node file = doc_.child("VTKFile");
        const pugi::xml_node image = imageData(file);
        const Encoding enc = encoding(file);
        std::array<int, 3> dims{};
        const auto transform = geometry(image, dims);
        const pugi::xml_node array = dataArray(image);
        const std::string what = at("DataArray '" + printable(attr(array, "Name")) + "'");
        VoxelLayout layout{dims, arrayType(attr(array, "type"), what + ": type"), enc.bigEndian};
        DensityBuilder builder(layout, options_.threshold, transform);
        readData(array, enc, builder, what);
        if (stats) *stats = builder.stats();
        return builder.grid();
    }

private:
    std::string at(const std::string& field) const { return path_ + ": " + field; }

    pugi::xml_node imageData(const pugi::xml_node& file) const {
        if (!file) throw Error(at("VTKFile: missing (not a VTK XML file)"));
        if (attr(file, "type") != "ImageData")
            throw Error(at("VTKFile type: '" + printable(attr(file, "type")) + "' is not ImageData"));
        const pugi::xml_node image = file.child("ImageData");
        if (!image) throw Error(at("ImageData: missing"));
        return image;
    }

    Encoding encoding(const pugi::xml_node& file) const {
        Encoding enc;
        const std::string order = attr(file, "byte_order");
        if (order != "LittleEndian" && order != "BigEndian" && !order.empty())
            throw Error(at("VTKFile byte_order: '" + printable(order) + "' is not LittleEndian or BigEndian"));
        enc.bigEndian = order == "BigEndian";
        const std::string header = attr(file, "header_type");
        if (header != "UInt32" && header != "UInt64" && !header.empty())
            throw Error(at("VTKFile header_type: '" + printable(header) + "' is not UInt32 or UInt64"));
        enc.headerBytes = header == "UInt64" ? 8 : 4;
        const std::string compressor = attr(file, "compressor");
        if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
            throw Error(at("VTKFile compressor: unsupported '" + printable(compressor) + "' (only vtkZLibDataCompressor)"));
        enc.zlib = !compressor.empty();
        return enc;
    }

    std::array<int, 6> extent(const pugi::xml_node& node, const char* name, const std::string& what) const {
        if (!node.attribute(name)) throw Error(at(what + ": missing"));
        const std::vector<double> e = numbers(attr(node, name), 6, at(what));
        std::array<int, 6> out{};
        for (int i = 0; i < 6; ++i) {
            if (e[i] != std::floor(e[i]) || std::abs(e[i]) > 1e9) throw Error(at(what + ": not integers"));
            out[i] = int(e[i]);
        }
        for (int a = 0; a < 3; ++a)
            if (out[2 * a + 1] < out[2 * a] || out[2 * a + 1] - out[2 * a] >= kMaxRawDim)
                throw Error(at(what + ": axis " + std::to_string(a) + " runs from " + std::to_string(out[2 * a]) + " to " +
                               std::to_string(out[2 * a + 1]) + " (needs 1.." + std::to_string(kMaxRawDim) + " points)"));
        return out;
    }

    openvdb::math::Transform::Ptr geometry(const pugi::xml_node& image, std::array<int, 3>& dims) const {
        const std::array<int, 6> whole = extent(image, "WholeExtent", "ImageData WholeExtent");
        for (int a = 0; a < 3; ++a) dims[a] = whole[2 * a + 1] - whole[2 * a] + 1;
        checkVoxelLimit(dims, options_.maxVoxels, at("ImageData WholeExtent"));
        const auto number = [&](const char* name, size_t n, std::vector<double> fallback) {
            return image.attribute(name) ? numbers(attr(image, name), n, at(std::string("ImageData ") + name)) : fallback;
        };
        const std::vector<double> origin = number("Origin", 3, {0, 0, 0});
        const std::vector<double> spacing = number("Spacing", 3, {1, 1, 1});
        const std::vector<double> dir = number("Direction", 9, {1, 0, 0, 0, 1, 0, 0, 0, 1});
        std::array<openvdb::Vec3d, 3> axes;
        openvdb::Vec3d o(origin[0], origin[1], origin[2]);
        for (int a = 0; a < 3; ++a) {
            for (int c = 0; c < 3; ++c) axes[a][c] = dir[3 * c + a] * spacing[a];  // world = O + D·diag(S)·ijk
        }
        for (int a = 0; a < 3; ++a) o += axes[a] * double(whole[2 * a]);  // voxel (0,0,0) is the extent's first point
        const pugi::xml_node piece = image.child("Piece");
        if (!piece) throw Error(at("Piece: missing"));
        if (piece.next_sibling("Piece")) throw Error(at("Piece: more than one (only single-piece files are supported)"));
        if (extent(piece, "Extent", "Piece Extent") != whole) throw Error(at("Piece Extent: differs from WholeExtent"));
        return indexToWorld(axes, o, at("ImageData Spacing/Direction"), at("ImageData Origin"));
    }

    pugi::xml_node dataArray(const pugi::xml_node& image) const {
        const pugi::xml_node points = image.child("Piece").child("PointData");
        std::string names;
        for (pugi::xml_node a = points.child("DataArray"); a; a = a.next_sibling("DataArray"))
            names += (names.empty() ? "" : ", ") + printable(attr(a, "Name"));
        if (!options_.array.empty()) {
            for (pugi::xml_node a = points.child("DataArray"); a; a = a.next_sibling("DataArray"))
                if (attr(a, "Name") == options_.array) return scalar(a);
            throw Error(at("PointData: no DataArray named '" + printable(options_.array) + "' (arrays: " + names + ")"));
        }
        const std::string active = attr(points, "Scalars");
        for (pugi::xml_node a = points.child("DataArray"); a; a = a.next_sibling("DataArray"))
            if (!active.empty() && attr(a, "Name") == active) return scalar(a);
        for (pugi::xml_node a = points.child("DataArray"); a; a = a.next_sibling("DataArray"))
            if (components(a) == 1) return a;
        throw Error(at("PointData: no scalar DataArray" + (names.empty() ? std::string() : " (arrays: " + names + ")")));
    }

    static long long components(const pugi::xml_node& a) {
        return a.attribute("NumberOfComponents") ? a.attribute("NumberOfComponents").as_llong() : 1;
    }
    pugi::xml_node scalar(const pugi::xml_node& a) const {
        if (components(a) != 1)
            throw Error(at("DataArray '" + printable(attr(a, "Name")) + "' NumberOfComponents: " +
                           std::to_string(components(a)) + " (only scalar arrays are supported)"));
        return a;
    }

    void readData(const pugi::xml_node& array, const Encoding& enc, DensityBuilder& builder, const std::string& what) {
        const std::string format = attr(array, "format");
        if (format == "ascii") return readAscii(array.child_value(), typeOf(array), builder, what);
        if (format == "binary") {
            MemorySource text(array.child_value());
            Base64Source bytes(text, what);
            readBinary(bytes, enc, builder, what);
            if (!bytes.exhausted()) throw Error(what + ": more data than its header gives");
            return;
        }
        if (format != "appended") throw Error(what + " format: unsupported '" + printable(format) + "' (ascii, binary or appended)");
        appended(array, enc, builder, what);
    }

    RawType typeOf(const pugi::xml_node& array) const { return arrayType(attr(array, "type"), at("DataArray type")); }

    void appended(const pugi::xml_node& array, const Encoding& enc, DensityBuilder& builder, const std::string& what) {
        if (!xml_.appended) throw Error(what + ": format appended, but the file has no AppendedData");
        if (!array.attribute("offset")) throw Error(what + " offset: missing (needed for appended data)");
        const uint64_t offset = uint64_t(parseInt(attr(array, "offset"), what + " offset", 0, 1LL << 50));
        std::error_code ec;
        const uint64_t size = std::filesystem::file_size(path_, ec);
        if (ec || offset > size - std::min(size, xml_.appendedStart))
            throw Error(what + " offset: " + std::to_string(offset) + " is past the end of the appended data");
        const std::string encodingName = attr(doc_.child("VTKFile").child("AppendedData"), "encoding");
        if (encodingName == "raw") {
            FileSource data(path_, xml_.appendedStart + offset, what);
            return readBinary(data, enc, builder, what);
        }
        if (encodingName != "base64")
            throw Error(at("AppendedData encoding: unsupported '" + printable(encodingName) + "' (raw or base64)"));
        FileSource chars(path_, xml_.appendedStart + offset, what);
        Base64Source bytes(chars, what);
        readBinary(bytes, enc, builder, what);
    }

    std::string path_;
    ConvertOptions options_;
    XmlPart xml_;
    pugi::xml_document doc_;
};

}  // namespace

openvdb::FloatGrid::Ptr convertVti(const std::string& path, const ConvertOptions& options, RawStats* stats) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
    return VtiReader(path, options).read(stats);
}

}  // namespace vdbsplat
