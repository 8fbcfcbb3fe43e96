// tests/image/test_png_writer.cpp — image/png_writer.h: the PNG encodePng writes decodes (through
// libpng) to exactly linearToSrgbCode of every channel, across the bands' boundaries and for
// every value the encoder must handle (NaN, negative, above 1); its chunks' CRCs and the zlib
// stream (Adler-32 included) are valid; and its bytes do not depend on the thread count.
#include <gtest/gtest.h>
#include <png.h>
#include <tbb/global_control.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "image/image.h"
#include "image/png_writer.h"

namespace vdbsplat {
namespace {

/// Every kind of value, and runs of equal pixels (what the run-length coder shortens), so the
/// Paeth filter takes each of its three predictors.
Image varied(int w, int h, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const float specials[] = {0.f, -0.5f, 1.f, 2.5f, NAN, INFINITY, -INFINITY, 1e-6f, 0.0031308f};
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            glm::vec4& p = img.at(x, y);
            const uint32_t pick = rng() % 8;
            if (pick == 0 && x > 0) p = img.at(x - 1, y);  // a run
            else if (pick == 1 && y > 0) p = img.at(x, y - 1);
            else if (pick == 2) p = glm::vec4(specials[rng() % 9], specials[rng() % 9], specials[rng() % 9], 1.f);
            else p = glm::vec4(u(rng), u(rng) * u(rng), float(x + y) / float(w + h), u(rng));
        }
    return img;
}

/// @p png decoded by libpng's simplified reader as 8-bit RGB (it checks the IDAT CRCs and the
/// zlib stream's Adler-32); empty with @p message set on failure.
std::vector<uint8_t> decodeRgb(const std::vector<uint8_t>& png, int& w, int& h, std::string& message) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, png.data(), png.size())) return message = image.message, std::vector<uint8_t>{};
    image.format = PNG_FORMAT_RGB;
    std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) {
        message = image.message;
        png_image_free(&image);
        return {};
    }
    w = int(image.width), h = int(image.height);
    return rgb;
}

uint32_t be32(const uint8_t* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }

TEST(PngWriter, DecodesToTheSrgbCodesOfEveryChannelAcrossBands) {
    // Heights around the band size (one band, exactly one, one row more, several), widths of one
    // pixel (only the first pixel's predictor) to wide rows.
    const int B = kPngBandRows;
    const std::pair<int, int> sizes[] = {{1, 1}, {2, 1}, {1, B - 1}, {3, B}, {5, B + 1}, {64, 2 * B + 7}, {333, 3}, {17, 4 * B}};
    uint32_t seed = 1;
    for (const auto& [w, h] : sizes) {
        const Image img = varied(w, h, seed++);
        int dw = 0, dh = 0;
        std::string message;
        const std::vector<uint8_t> rgb = decodeRgb(encodePng(img), dw, dh, message);
        ASSERT_EQ(dw, w) << w << "x" << h << ": " << message;
        ASSERT_EQ(dh, h);
        int wrong = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c) {
                    const uint8_t want = linearToSrgbCode(img.at(x, y)[c]);
                    const uint8_t got = rgb[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)];
                    if (got != want && ++wrong <= 5)
                        ADD_FAILURE() << w << "x" << h << " (" << x << ", " << y << ")[" << c << "]: " << int(got) << " against " << int(want);
                }
    }
}

TEST(PngWriter, ChunksAndStreamAreValid) {
    const Image img = varied(100, 3 * kPngBandRows + 5, 7);
    const std::vector<uint8_t> png = encodePng(img);
    const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    ASSERT_GT(png.size(), 8u);
    ASSERT_EQ(std::memcmp(png.data(), signature, 8), 0);
    std::vector<std::string> types;
    std::vector<uint8_t> stream;
    for (size_t at = 8; at < png.size();) {
        ASSERT_LE(at + 12, png.size());
        const uint32_t n = be32(&png[at]);
        ASSERT_LE(at + 12 + n, png.size());
        const std::string type(reinterpret_cast<const char*>(&png[at + 4]), 4);
        const uint32_t crc = uint32_t(crc32(0L, &png[at + 4], uInt(4 + n)));
        EXPECT_EQ(crc, be32(&png[at + 8 + n])) << "chunk " << types.size() << " " << type;
        if (type == "IDAT") stream.insert(stream.end(), png.begin() + ptrdiff_t(at + 8), png.begin() + ptrdiff_t(at + 8 + n));
        types.push_back(type);
        at += 12 + n;
    }
    ASSERT_GE(types.size(), 4u);
    EXPECT_EQ(types.front(), "IHDR");
    EXPECT_EQ(types[1], "sRGB");
    EXPECT_EQ(types.back(), "IEND");
    for (size_t i = 2; i + 1 < types.size(); ++i) EXPECT_EQ(types[i], "IDAT") << i;
    EXPECT_EQ(types.size(), size_t(2 + 4 + 1 + 1));  // 4 bands, the Adler-32's IDAT, IEND
    // One zlib stream: inflated whole (zlib checks the Adler-32), one filter byte and 3 bytes a
    // pixel per row, every row Paeth-filtered.
    const size_t lineBytes = 1 + 3 * size_t(img.width);
    std::vector<uint8_t> raw(lineBytes * size_t(img.height) + 1);
    uLongf rawSize = uLongf(raw.size());
    ASSERT_EQ(uncompress(raw.data(), &rawSize, stream.data(), uLong(stream.size())), Z_OK);
    ASSERT_EQ(rawSize, lineBytes * size_t(img.height));
    for (int y = 0; y < img.height; ++y) EXPECT_EQ(raw[size_t(y) * lineBytes], 4) << "row " << y;
}

TEST(PngWriter, BytesDoNotDependOnTheThreadCount) {
    const Image img = varied(257, 5 * kPngBandRows + 3, 11);
    std::vector<uint8_t> one, two, eight;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = encodePng(img);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = encodePng(img);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 8);
        eight = encodePng(img);
    }
    EXPECT_EQ(one, two);
    EXPECT_EQ(one, eight);
}

TEST(PngWriter, RefusesAnEmptyImage) {
    EXPECT_THROW(encodePng(Image(0, 4)), std::invalid_argument);
    EXPECT_THROW(encodePng(Image(4, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace vdbsplat
