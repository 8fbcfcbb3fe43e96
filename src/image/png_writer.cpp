// image/png_writer.cpp — encodePng: sRGB codes, Paeth filter and deflate per band of rows, in
// parallel; the file assembled in order (image/png_writer.h).
#include "image/png_writer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

#include "image/image.h"

namespace vdbsplat {

namespace {

/// 8-bit sRGB codes, lround(255·linearToSrgb(v)), by two tables. The code is non-decreasing in v,
/// so it is the number of codes k ≥ 1 whose threshold — the least float with that code or more —
/// is at most v. The floats of (0, 1) with the same sign, exponent and top 7 mantissa bits
/// (a bucket, 0.8 % wide) span at most two codes (the steepest, near 1, is 106 codes per unit of
/// ln v: 0.83 a bucket), so the code is the bucket's first code, plus one where v reaches the next
/// code's threshold: a table read and a comparison, where an 8-step binary search over the
/// thresholds was 8 dependent reads (half of a 1024² PNG's encoding; docs/performance.md, session
/// 32) and a powf per channel before that (session 17). The same code for every float: every
/// float of [0, 1] checked against the formula (the disabled test of tests/image/test_image.cpp
/// runs it); NaN and v ≤ 0 give 0, v ≥ 1 gives 255.
class SrgbEncoder {
public:
    SrgbEncoder() {
        first_[0] = -INFINITY;
        for (int k = 1; k < 256; ++k) {
            // The least non-negative float (ordered as its bits) whose code is at least k.
            uint32_t lo = 0, hi = 0x3f800000u;  // code(0) = 0 < k ≤ 255 = code(1)
            while (lo + 1 < hi) {
                const uint32_t mid = lo + (hi - lo) / 2;
                (code(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
            }
            first_[size_t(k)] = std::bit_cast<float>(hi);
        }
        first_[256] = INFINITY;  // no code above 255: the comparison below never passes it
        for (uint32_t b = 0; b < kBuckets; ++b) bucket_[b] = search(std::bit_cast<float>(b << kBucketShift));
    }
    /// The formula itself (the oracle of the tables; image.h's linearToSrgb, rounded).
    static int code(float v) { return int(static_cast<uint8_t>(std::lround(255.0f * linearToSrgb(v)))); }
    uint8_t operator()(float v) const {
        if (!(v > 0.f)) return 0;  // NaN too, as the formula's lround(NaN) cast to a byte
        if (!(v < 1.f)) return 255;
        const int k = bucket_[std::bit_cast<uint32_t>(v) >> kBucketShift];
        return uint8_t(k + (v >= first_[size_t(k) + 1] ? 1 : 0));
    }

private:
    static constexpr int kBucketShift = 16;                            ///< sign, exponent, 7 mantissa bits
    static constexpr uint32_t kBuckets = 0x3f800000u >> kBucketShift;  ///< the buckets of [0, 1)
    /// The code of @p v ≥ 0 by binary search over the thresholds.
    uint8_t search(float v) const {
        int k = 0;
        for (int step = 128; step > 0; step >>= 1)
            if (v >= first_[size_t(k + step)]) k += step;
        return uint8_t(k);
    }
    std::array<float, 257> first_;
    std::array<uint8_t, kBuckets> bucket_;
};

const SrgbEncoder& srgbEncoder() {
    static const SrgbEncoder encoder;  // 255 binary searches, ~0.1 ms, once per process
    return encoder;
}

void put32(std::vector<uint8_t>& out, uint32_t v) {
    const uint8_t b[4] = {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
    out.insert(out.end(), b, b + 4);
}

/// Opens a chunk (PNG §5.3) at the end of @p out: its length (set by closeChunk) and @p type.
size_t openChunk(std::vector<uint8_t>& out, const char (&type)[5]) {
    const size_t start = out.size();
    put32(out, 0);
    out.insert(out.end(), type, type + 4);
    return start;
}
/// Closes the chunk opened at @p start, its data being the rest of @p out: the length, and the
/// CRC-32 of type and data appended.
void closeChunk(std::vector<uint8_t>& out, size_t start) {
    const size_t size = out.size() - start - 8;
    const uint8_t length[4] = {uint8_t(size >> 24), uint8_t(size >> 16), uint8_t(size >> 8), uint8_t(size)};
    std::memcpy(out.data() + start, length, 4);
    put32(out, uint32_t(crc32_z(crc32(0L, Z_NULL, 0), out.data() + start + 4, size + 4)));
}
void putChunk(std::vector<uint8_t>& out, const char (&type)[5], const uint8_t* data, size_t size) {
    const size_t start = openChunk(out, type);
    if (size) out.insert(out.end(), data, data + size);
    closeChunk(out, start);
}

/// What the encoder reads: @p data placed at (x0, y0) of a width × height image, zero elsewhere
/// (an Image is its own whole window).
struct PixelRows {
    const Image& data;
    int x0 = 0, y0 = 0, width = 0, height = 0;
};

/// Row @p y of @p image as 8-bit sRGB codes over black (RGB); a zero pixel's code is 0.
void encodeRow(const PixelRows& image, int y, uint8_t* rgb) {
    const SrgbEncoder& encode = srgbEncoder();
    const Image& data = image.data;
    const int v = y - image.y0;
    uint8_t* const end = rgb + 3 * size_t(image.width);
    if (v < 0 || v >= data.height || data.width == 0) {
        std::fill(rgb, end, uint8_t(0));
        return;
    }
    uint8_t* out = rgb + 3 * size_t(image.x0);
    std::fill(rgb, out, uint8_t(0));
    const glm::vec4* px = &data.pixels[size_t(v) * size_t(data.width)];
    for (int x = 0; x < data.width; ++x)
        for (int c = 0; c < 3; ++c) out[3 * x + c] = encode(px[x][c]);
    std::fill(out + 3 * size_t(data.width), end, uint8_t(0));
}

/// The Paeth filter (PNG §9.4) of @p row (@p n bytes, 3 per pixel) against @p prior (the row
/// above, zeros above the first row): filter byte 4, then each byte minus its predictor.
void paethRow(const uint8_t* row, const uint8_t* prior, size_t n, uint8_t* out) {
    out[0] = 4;
    ++out;
    for (size_t i = 0; i < std::min<size_t>(3, n); ++i) out[i] = uint8_t(row[i] - prior[i]);  // a = c = 0: b
    for (size_t i = 3; i < n; ++i) {  // in 16-bit lanes where vectorised (|a + b − 2c| ≤ 510)
        const int16_t a = row[i - 3], b = prior[i], c = prior[i - 3];
        const int16_t pa = int16_t(std::abs(b - c)), pb = int16_t(std::abs(a - c)), pc = int16_t(std::abs(a + b - 2 * c));
        const int16_t predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
        out[i] = uint8_t(row[i] - predictor);
    }
}

/// One thread's deflate state (raw deflate, run-length strategy), reset for every band.
struct Deflater {
    z_stream z{};
    bool ready = false;
    Deflater() {
        if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_RLE) != Z_OK) throw std::bad_alloc();
        ready = true;
    }
    ~Deflater() {
        if (ready) deflateEnd(&z);
    }
    Deflater(const Deflater&) = delete;
    Deflater& operator=(const Deflater&) = delete;
};

/// A band's part of the file: its IDAT chunk whole (length, type, data, CRC), the Adler-32 of
/// its filtered rows, and their length.
struct Band {
    std::vector<uint8_t> chunk;
    uLong adler = 1;
    size_t rawBytes = 0;
};

/// Rows [@p y0, @p y1) of @p image, filtered and deflated; @p last ends the stream (else a sync
/// flush ends the band on a byte boundary); @p first carries the zlib header before them.
void encodeBand(const PixelRows& image, int y0, int y1, bool first, bool last, Deflater& deflater, Band& band) {
    const size_t rowBytes = size_t(image.width) * 3, lineBytes = rowBytes + 1;
    std::vector<uint8_t> rgb(2 * rowBytes, 0), filtered(size_t(y1 - y0) * lineBytes);
    uint8_t* prior = rgb.data();  // zeros above the first row
    uint8_t* row = rgb.data() + rowBytes;
    if (y0 > 0) encodeRow(image, y0 - 1, prior);
    for (int y = y0; y < y1; ++y) {
        encodeRow(image, y, row);
        paethRow(row, prior, rowBytes, filtered.data() + size_t(y - y0) * lineBytes);
        std::swap(row, prior);
    }
    band.rawBytes = filtered.size();
    band.adler = adler32_z(adler32(0L, Z_NULL, 0), filtered.data(), filtered.size());

    z_stream& z = deflater.z;
    if (deflateReset(&z) != Z_OK) throw std::bad_alloc();
    std::vector<uint8_t>& out = band.chunk;
    out.clear();
    const size_t chunk = openChunk(out, "IDAT");
    if (first) out.push_back(0x78), out.push_back(0x9c);  // zlib header: deflate, 32 KiB window, default level (RFC 1950)
    size_t used = out.size();
    out.resize(used + deflateBound(&z, uLong(filtered.size())) + 64);
    z.next_in = filtered.data();
    z.avail_in = uInt(filtered.size());
    const int flush = last ? Z_FINISH : Z_SYNC_FLUSH;
    while (true) {
        z.next_out = out.data() + used;
        z.avail_out = uInt(out.size() - used);
        const int status = deflate(&z, flush);
        if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR) throw std::bad_alloc();
        used = out.size() - z.avail_out;
        if (status == Z_STREAM_END || (!last && z.avail_in == 0 && z.avail_out > 0)) break;
        out.resize(out.size() + out.size() / 2 + 64);  // more room than deflateBound promised: keep going
    }
    out.resize(used);
    closeChunk(out, chunk);
}

/// The PNG file of @p image (encodePng's two forms).
std::vector<uint8_t> encodeRows(const PixelRows& image) {
    if (image.width < 1 || image.height < 1) throw std::invalid_argument("empty image");
    const int bands = (image.height + kPngBandRows - 1) / kPngBandRows;
    std::vector<Band> parts(static_cast<size_t>(bands));
    tbb::enumerable_thread_specific<Deflater> deflaters;
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
        Deflater& deflater = deflaters.local();
        for (int b = r.begin(); b < r.end(); ++b)
            encodeBand(image, b * kPngBandRows, std::min(image.height, (b + 1) * kPngBandRows), b == 0, b == bands - 1,
                       deflater, parts[size_t(b)]);
    });

    std::vector<uint8_t> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<uint8_t> ihdr;
    put32(ihdr, uint32_t(image.width)), put32(ihdr, uint32_t(image.height));
    ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, adaptive filtering, not interlaced
    putChunk(file, "IHDR", ihdr.data(), ihdr.size());
    const uint8_t perceptual = 0;
    putChunk(file, "sRGB", &perceptual, 1);
    size_t total = file.size() + 12 + 4 + 12;
    for (const Band& part : parts) total += part.chunk.size();
    file.reserve(total);
    uLong adler = 1;
    for (const Band& part : parts) {
        file.insert(file.end(), part.chunk.begin(), part.chunk.end());
        adler = adler32_combine(adler, part.adler, z_off_t(part.rawBytes));
    }
    std::vector<uint8_t> trailer;  // the stream's Adler-32, in an IDAT of its own
    put32(trailer, uint32_t(adler));
    putChunk(file, "IDAT", trailer.data(), trailer.size());
    putChunk(file, "IEND", nullptr, 0);
    return file;
}

}  // namespace

uint8_t linearToSrgbCode(float v) { return srgbEncoder()(v); }

std::vector<uint8_t> encodePng(const Image& image) { return encodeRows({image, 0, 0, image.width, image.height}); }

std::vector<uint8_t> encodePng(const WindowedImage& image) {
    return encodeRows({image.data, image.x0, image.y0, image.width, image.height});
}

}  // namespace vdbsplat
