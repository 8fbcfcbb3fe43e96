// scripts/png-options.cpp — encode time and file size of PNG settings on real renders: each
// PNG's rows are read back (8-bit RGB) and written again with libpng's defaults (adaptive
// filters, deflate level 6: what vdbsplat wrote before session 17) and with single filters,
// lower levels and zlib's run-length strategy (vdbsplat's choice: Paeth + Z_RLE), best of 5.
// Not part of the build (docs/performance.md, session 17):
//   g++ -O2 scripts/png-options.cpp -o /tmp/png-options -lpng -lz
//   /tmp/png-options out/a.png out/b.png ...
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

namespace {

struct Setting {
    const char* name;
    int filters, level, strategy;  // -1: libpng's default
};

std::vector<png_byte> readRgb(const char* path, png_uint_32& w, png_uint_32& h) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path)) return {};
    image.format = PNG_FORMAT_RGB;
    std::vector<png_byte> rgb(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) rgb.clear();
    w = image.width, h = image.height;
    png_image_free(&image);
    return rgb;
}

/// Milliseconds to write the rows to @p out with @p s (sRGB chunk as vdbsplat writes it); its size in @p bytes.
double encode(const std::vector<png_byte>& rgb, png_uint_32 w, png_uint_32 h, const Setting& s, const char* out, long& bytes) {
    const auto t0 = std::chrono::steady_clock::now();
    std::FILE* f = std::fopen(out, "wb");
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_set_IHDR(png, info, w, h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    if (s.filters >= 0) png_set_filter(png, PNG_FILTER_TYPE_BASE, s.filters);
    if (s.level >= 0) png_set_compression_level(png, s.level);
    if (s.strategy >= 0) png_set_compression_strategy(png, s.strategy);
    png_write_info(png, info);
    for (png_uint_32 y = 0; y < h; ++y) png_write_row(png, rgb.data() + size_t(y) * w * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    bytes = std::ftell(f);
    std::fclose(f);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() * 1e3;
}

}  // namespace

int main(int argc, char** argv) {
    const Setting settings[] = {
        {"libpng default", -1, -1, -1},          {"Paeth + Z_RLE", PNG_FILTER_PAETH, -1, Z_RLE},
        {"Paeth, level 3", PNG_FILTER_PAETH, 3, -1}, {"Paeth, level 2", PNG_FILTER_PAETH, 2, -1},
        {"Paeth, level 6", PNG_FILTER_PAETH, 6, -1}, {"Sub, level 3", PNG_FILTER_SUB, 3, -1},
        {"Up + Z_RLE", PNG_FILTER_UP, -1, Z_RLE},    {"none, level 1", PNG_FILTER_NONE, 1, -1},
    };
    for (int a = 1; a < argc; ++a) {
        png_uint_32 w = 0, h = 0;
        const std::vector<png_byte> rgb = readRgb(argv[a], w, h);
        if (rgb.empty()) {
            std::fprintf(stderr, "png-options: %s: not a readable PNG\n", argv[a]);
            return 1;
        }
        std::printf("%s (%ux%u)\n", argv[a], w, h);
        for (const Setting& s : settings) {
            long bytes = 0;
            double best = 1e30;
            for (int run = 0; run < 5; ++run) best = std::min(best, encode(rgb, w, h, s, "/tmp/png-options.png", bytes));
            std::printf("  %-16s %8.2f ms %9ld B\n", s.name, best, bytes);
        }
    }
}
