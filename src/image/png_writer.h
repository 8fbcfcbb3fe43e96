// image/png_writer.h — an Image as the bytes of an 8-bit RGB PNG file, encoded on every core.
// Owns: encodePng (sRGB codes by table, Paeth-filtered rows, deflate with zlib's run-length
// strategy, in fixed bands of rows compressed independently and joined into one zlib stream)
// and linearToSrgbCode's table (image/image.h).
//
// Why: libpng writes a PNG on one thread, and at 1024² the write took as long as a far render
// (18–24 ms of an 80 ms process: the sRGB codes, its Paeth filter and the deflate, one after the
// other; docs/performance.md, session 32). The file format allows what pigz does: each band of
// rows is deflated on its own, ended by a sync flush (an empty stored block that aligns it to a
// byte, RFC 1951 §3.2.4) except the last, so the bands' streams concatenate into one stream; the
// Adler-32 of the whole is combined from the bands' (RFC 1950), and each band is an IDAT chunk of
// its own (PNG §11.2.4: consecutive IDATs form one stream). The bands are fixed rows, not
// threads, so the bytes do not depend on the thread count.
#pragma once
#include <cstdint>
#include <vector>

namespace vdbsplat {

struct Image;
struct WindowedImage;

/// Rows per independently deflated band (the last may have fewer). Each band restarts the
/// run-length coder and its Huffman tables: ~100 bytes per band against one stream.
inline constexpr int kPngBandRows = 32;

/// @brief The PNG file (signature to IEND) of @p image: 8-bit RGB, composited over black (the
/// premultiplied colour is the colour over black), the sRGB chunk, no alpha.
/// @throw std::invalid_argument for an empty image; std::bad_alloc when zlib has no memory.
std::vector<uint8_t> encodePng(const Image& image);
/// @brief The same file as encodePng(image.full()), read from the data window and zeros.
std::vector<uint8_t> encodePng(const WindowedImage& image);

}  // namespace vdbsplat
