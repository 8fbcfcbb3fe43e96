// tests/image/test_image.cpp — image/image.h: PNG/EXR round trips, and the input checks of
// readImage (volume, oversized and truncated files refused before any pixel is read, issue
// 12) and the output rules of writeImage (through symbolic links, never over a FIFO). The
// EXR and PNG fixtures that vdbsplat never writes (several parts, deep, luminance, 16-bit,
// alpha) are made here with OpenEXR and libpng themselves.
#include <gtest/gtest.h>
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <ImfChannelList.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <png.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <functional>

#include <sys/stat.h>

#include <tbb/global_control.h>

#include "image/image.h"
#include "support/cli.h"
#include "support/error_of.h"
#include "volume/generate.h"
#include "volume/grid.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::errorOf;

Image ramp(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.at(x, y) = glm::vec4(float(x) / w, float(y) / h, 0.25f, 1.f);
    return img;
}

TEST(Image, ExrRoundTripsExactly) {
    test::ScratchDir dir("image");
    const Image a = ramp(7, 5);
    writeImage(dir.path("a.exr"), a);
    const Image b = readImage(dir.path("a.exr"));
    ASSERT_EQ(b.width, 7);
    ASSERT_EQ(b.height, 5);
    for (size_t i = 0; i < a.pixels.size(); ++i) EXPECT_EQ(a.pixels[i], b.pixels[i]) << i;
}

// OpenImageIO (vdbsplat's image library before libpng and OpenEXR) read a .vdb as a volume
// image (depth > 1): readImage ignored the depth and wrote depth times past its buffer.
TEST(Image, VolumeImageIsRefused) {
    test::ScratchDir dir("image");
    initOpenVdb();
    GenerateOptions o;
    o.kind = "sphere";
    o.res = 33;
    writeVolume(dir.path("s.vdb"), generateVolume(o));
    fs::copy_file(dir.path("s.vdb"), dir.path("s.png"));
    for (const char* name : {"s.vdb", "s.png"}) {
        const std::string msg = errorOf([&] { readImage(dir.path(name)); });
        EXPECT_NE(msg.find(dir.path(name)), std::string::npos) << msg;
        EXPECT_NE(msg.find("volume image"), std::string::npos) << msg;
    }
}

// compare reads PNG and EXR only, chosen by content, whatever the name says.
TEST(Image, OnlyPngAndExrContentIsRead) {
    test::ScratchDir dir("image");
    test::spit(dir.path("text.png"), "P3\n1 1\n255\n0 0 0\n");  // a PPM named .png
    const std::string msg = errorOf([&] { readImage(dir.path("text.png")); });
    EXPECT_NE(msg.find("not a PNG or EXR"), std::string::npos) << msg;
    writeImage(dir.path("real.exr"), ramp(2, 2));
    fs::copy_file(dir.path("real.exr"), dir.path("named.png"));  // an EXR named .png is still read
    const Image named = readImage(dir.path("named.png"));
    ASSERT_EQ(named.width, 2);
    EXPECT_EQ(named.pixels[3], ramp(2, 2).pixels[3]);  // linear, as EXR: not decoded as sRGB
}

TEST(Image, SidesAboveTheLimitAreRefusedFromTheHeader) {
    test::ScratchDir dir("image");
    // A real (tiny) image passes; the limit is checked on the header's size.
    writeImage(dir.path("ok.png"), ramp(kMaxImageSide > 4 ? 4 : 1, 2));
    EXPECT_EQ(readImage(dir.path("ok.png")).width, 4);
    std::string bytes = test::slurp(dir.path("ok.png"));
    // Patch the IHDR width (bytes 16..19, big-endian) to 20000: refused before the CRC or pixels matter.
    bytes[16] = 0, bytes[17] = 0, bytes[18] = char(20000 >> 8), bytes[19] = char(20000 & 255);
    test::spit(dir.path("wide.png"), bytes);
    const std::string msg = errorOf([&] { readImage(dir.path("wide.png")); });
    EXPECT_NE(msg.find("wide.png"), std::string::npos) << msg;
}

/// Writes a @p w x @p h EXR of one FLOAT channel per name in @p channels, values from @p value.
void writeExrChannels(const std::string& path, int w, int h, const std::vector<std::string>& channels,
                      const std::function<float(int x, int y, size_t c)>& value) {
    Imf::Header header(w, h);
    std::vector<float> data(size_t(w) * h * channels.size());
    Imf::FrameBuffer frame;
    for (size_t c = 0; c < channels.size(); ++c) {
        header.channels().insert(channels[c], Imf::Channel(Imf::FLOAT));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) data[(size_t(y) * w + x) * channels.size() + c] = value(x, y, c);
        frame.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data.data() + c),
                                             sizeof(float) * channels.size(), sizeof(float) * channels.size() * w));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(h);
}

TEST(Image, PngRoundTripsToTheEncodedSrgbValues) {
    test::ScratchDir dir("image");
    const Image a = ramp(9, 4);
    writeImage(dir.path("a.png"), a);
    const Image b = readImage(dir.path("a.png"));
    ASSERT_EQ(b.width, 9);
    ASSERT_EQ(b.height, 4);
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            // 8-bit sRGB: the value read back is the encoded one, decoded with the same curve.
            const float encoded = std::round(255.0f * linearToSrgb(a.pixels[i][c])) / 255.0f;
            EXPECT_FLOAT_EQ(b.pixels[i][c], srgbToLinear(encoded)) << i;
        }
    for (const glm::vec4& p : b.pixels) EXPECT_EQ(p.w, 1.0f);
}

/// A @p w × @p h image of noise in R and B (a fixed LCG from @p seed), G = @p green: every code,
/// no runs, for the writers' round trips.
Image noiseImage(int w, int h, uint32_t seed, float green) {
    Image img(w, h);
    for (glm::vec4& p : img.pixels) {
        seed = seed * 1664525u + 1013904223u;
        p = glm::vec4(float(seed >> 8) / float(1u << 24), green, float(seed % 977) / 977.f, 1.f);
    }
    return img;
}

/// The formula the PNG codes stand for: lround(255·linearToSrgb(v)) as a byte (NaN: 0).
int srgbCodeByFormula(float v) { return int(static_cast<uint8_t>(std::lround(255.0f * linearToSrgb(v)))); }

// linearToSrgbCode finds a code by the table of its thresholds; it must give the formula's code
// for every float (checked exhaustively over [0, 1] once, docs/performance.md session 17). Here:
// every 61st float of [0, 1], every float within 4096 of each code's boundary, and the ends.
TEST(Image, SrgbCodesByTableAreTheFormulas) {
    int checked = 0, wrong = 0;
    const auto check = [&](float v) {
        ++checked;
        if (linearToSrgbCode(v) != srgbCodeByFormula(v) && ++wrong <= 5)
            ADD_FAILURE() << "v = " << v << ": " << int(linearToSrgbCode(v)) << " against " << srgbCodeByFormula(v);
    };
    for (uint32_t bits = 0; bits <= 0x3f800000u; bits += 61) check(std::bit_cast<float>(bits));
    for (int k = 1; k < 256; ++k) {
        const uint32_t at = std::bit_cast<uint32_t>(srgbToLinear((float(k) - 0.5f) / 255.0f));
        for (uint32_t bits = at - 4096; bits <= at + 4096; ++bits) check(std::bit_cast<float>(bits));
    }
    for (const float v : {0.f, -0.f, -1e-30f, -1.f, -INFINITY, 1.f, 1.0000001f, 7.f, INFINITY, NAN, -NAN}) check(v);
    EXPECT_EQ(wrong, 0) << "of " << checked;
    EXPECT_EQ(linearToSrgbCode(1.f), 255);
    EXPECT_EQ(linearToSrgbCode(NAN), 0);
}

// The whole of [0, 1], every float (about 15 s on one core; not part of the suite): run with
// build/test_image --gtest_also_run_disabled_tests --gtest_filter='*EveryFloat*'.
TEST(Image, DISABLED_SrgbCodesOfEveryFloatInZeroOneAreTheFormulas) {
    uint64_t wrong = 0;
    for (uint32_t bits = 0; bits <= 0x3f800000u; ++bits) {
        const float v = std::bit_cast<float>(bits);
        wrong += linearToSrgbCode(v) != srgbCodeByFormula(v);
    }
    EXPECT_EQ(wrong, 0u);
}

// The writer (Paeth rows, run-length deflate) on a render-like image: black borders, flat runs,
// gradients and noise in a 300×200 frame: every byte read back is the code written.
TEST(Image, PngKeepsEveryCodeOfALargeImage) {
    test::ScratchDir dir("image");
    Image a = noiseImage(300, 200, 12345, 0.f);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            glm::vec4& p = a.at(x, y);
            const bool border = x < 40 || y < 30;
            p = border ? glm::vec4(0.f) : glm::vec4(float(x) / a.width, p.x, y % 17 < 8 ? 0.5f : 1e-3f, 1.f);
        }
    writeImage(dir.path("a.png"), a);
    const Image b = readImage(dir.path("a.png"));
    ASSERT_EQ(b.width, a.width);
    ASSERT_EQ(b.height, a.height);
    int wrong = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c)
            wrong += b.pixels[i][c] != srgbToLinear(float(srgbCodeByFormula(a.pixels[i][c])) / 255.0f);
    EXPECT_EQ(wrong, 0);
}

// A render's image is stored as its data window (WindowedImage): full() must place the window
// and leave the rest zero, and a window that does not lie inside its image is refused.
TEST(Image, WindowedImagePlacesItsWindowAndZerosTheRest) {
    const Image window = noiseImage(5, 3, 99, 0.5f);
    const WindowedImage w(window, 2, 4, 9, 8);
    const Image full = w.full();
    ASSERT_EQ(full.width, 9);
    ASSERT_EQ(full.height, 8);
    int placed = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 9; ++x) {
            const bool inside = x >= 2 && x < 7 && y >= 4 && y < 7;
            const glm::vec4 expected = inside ? window.at(x - 2, y - 4) : glm::vec4(0.f);
            EXPECT_EQ(full.at(x, y), expected) << x << "," << y;
            EXPECT_EQ(w.at(x, y), expected) << x << "," << y;
            placed += inside;
        }
    EXPECT_EQ(placed, 15);
    // The whole window moves out as it is.
    const Image moved = WindowedImage(window).full();
    EXPECT_TRUE(std::equal(window.pixels.begin(), window.pixels.end(), moved.pixels.begin()));
    // An empty window (no columns, or no rows) anywhere inside: all transparent.
    for (const Image& empty : {Image(0, 3), Image(4, 0)}) {
        const Image none = WindowedImage(empty, 9 - empty.width, 8 - empty.height, 9, 8).full();
        ASSERT_EQ(none.pixels.size(), 72u);
        EXPECT_TRUE(std::all_of(none.pixels.begin(), none.pixels.end(), [](const glm::vec4& p) { return p == glm::vec4(0.f); }));
    }
    EXPECT_NE(errorOf([&] { WindowedImage(window, 5, 4, 9, 8); }).find("does not lie inside a 9x8 image"), std::string::npos);
    EXPECT_NE(errorOf([&] { WindowedImage(window, 2, 6, 9, 8); }).find("window at (2, 6)"), std::string::npos);
    EXPECT_NE(errorOf([&] { WindowedImage(window, -1, 0, 9, 8); }).find("does not lie inside"), std::string::npos);
}

// The PNG of a data window is encoded from the window and zeros: the same file, byte for byte, as
// the PNG of its full image, for windows at the corners, the edges, across band boundaries
// (kPngBandRows), one pixel, empty, and the whole image; the EXR likewise reads back the full image.
TEST(Image, WindowedPngIsTheFullImagesFileByteForByte) {
    test::ScratchDir dir("image");
    struct Case {
        int w, h, x0, y0, width, height;
    };
    const Case cases[] = {{30, 20, 0, 0, 100, 70},  {30, 20, 70, 50, 100, 70}, {100, 3, 0, 31, 100, 70},
                          {7, 70, 93, 0, 100, 70},  {1, 1, 50, 33, 100, 70},   {0, 0, 0, 0, 100, 70},
                          {100, 70, 0, 0, 100, 70}, {45, 40, 17, 29, 62, 97}};
    int i = 0;
    for (const Case& c : cases) {
        Image window = noiseImage(c.w, c.h, 31u + uint32_t(i), 0.75f);
        if (c.w > 2) window.at(1, 0) = glm::vec4(0.f);  // a zero inside the window, too
        const WindowedImage w(window, c.x0, c.y0, c.width, c.height);
        const std::string tag = std::to_string(i++);
        writeImage(dir.path("w" + tag + ".png"), w);
        writeImage(dir.path("f" + tag + ".png"), w.full());
        const std::string windowed = test::slurp(dir.path("w" + tag + ".png")), full = test::slurp(dir.path("f" + tag + ".png"));
        ASSERT_GT(full.size(), 50u) << tag;
        EXPECT_TRUE(windowed == full) << "case " << tag;
        writeImage(dir.path("w" + tag + ".exr"), w);
        const Image back = readImage(dir.path("w" + tag + ".exr")), expected = w.full();
        ASSERT_EQ(back.pixels.size(), expected.pixels.size()) << tag;
        EXPECT_TRUE(std::equal(back.pixels.begin(), back.pixels.end(), expected.pixels.begin())) << tag;
    }
    // An unknown extension is refused before anything is written, as for an Image.
    EXPECT_NE(errorOf([&] { writeImage(dir.path("x.tif"), WindowedImage(noiseImage(2, 2, 1, 0.f), 0, 0, 4, 4)); }).find("x.tif"),
              std::string::npos);
    EXPECT_FALSE(fs::exists(dir.path("x.tif")));
}

// EXR line blocks are compressed on TBB's number of threads; the file must not depend on it.
TEST(Image, ExrBytesDoNotDependOnTheThreadCount) {
    test::ScratchDir dir("image");
    const Image a = noiseImage(257, 190, 7, 0.25f);
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        writeImage(dir.path("one.exr"), a);
    }
    {
        tbb::global_control four(tbb::global_control::max_allowed_parallelism, 4);
        writeImage(dir.path("four.exr"), a);
    }
    const std::string one = test::slurp(dir.path("one.exr")), four = test::slurp(dir.path("four.exr"));
    ASSERT_GT(one.size(), 100000u);
    EXPECT_TRUE(one == four);
    const Image b = readImage(dir.path("four.exr"));
    ASSERT_EQ(b.pixels.size(), a.pixels.size());
    EXPECT_TRUE(std::equal(a.pixels.begin(), a.pixels.end(), b.pixels.begin()));
}

TEST(Image, ExrCarriesTheMetadataAsStringAttributes) {
    test::ScratchDir dir("image");
    writeImage(dir.path("m.exr"), ramp(3, 2), {{"mode", "hybrid"}, {"seconds", "0.25"}});
    Imf::InputFile file(dir.path("m.exr").c_str());
    const auto* mode = file.header().findTypedAttribute<Imf::StringAttribute>("vdbsplat:mode");
    ASSERT_NE(mode, nullptr);
    EXPECT_EQ(mode->value(), "hybrid");
    EXPECT_EQ(file.header().compression(), Imf::ZIP_COMPRESSION);
    EXPECT_NE(file.header().channels().findChannel("A"), nullptr);
}

TEST(Image, ExrLuminanceAndAlphaChannelsAreRead) {
    test::ScratchDir dir("image");
    writeExrChannels(dir.path("y.exr"), 4, 3, {"Y"}, [](int x, int y, size_t) { return 0.1f * x + y; });
    const Image grey = readImage(dir.path("y.exr"));
    ASSERT_EQ(grey.width, 4);
    EXPECT_EQ(grey.at(3, 2), glm::vec4(2.3f, 2.3f, 2.3f, 1.0f));
    writeExrChannels(dir.path("rgba.exr"), 2, 2, {"A", "B", "G", "R"}, [](int, int, size_t c) { return 0.2f * (c + 1); });
    EXPECT_EQ(readImage(dir.path("rgba.exr")).at(1, 1), glm::vec4(0.8f, 0.6f, 0.4f, 0.2f));  // by name, not order
    writeExrChannels(dir.path("uv.exr"), 2, 2, {"U", "V"}, [](int, int, size_t) { return 0.f; });
    const std::string msg = errorOf([&] { readImage(dir.path("uv.exr")); });
    EXPECT_NE(msg.find("uv.exr"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no R, G, B or Y"), std::string::npos) << msg;
}

TEST(Image, ExrWithSeveralPartsOrDeepPixelsIsRefused) {
    test::ScratchDir dir("image");
    std::vector<Imf::Header> headers(2, Imf::Header(2, 2));
    for (size_t i = 0; i < headers.size(); ++i) {
        headers[i].setName("part" + std::to_string(i));
        headers[i].setType(Imf::SCANLINEIMAGE);
        headers[i].channels().insert("R", Imf::Channel(Imf::FLOAT));
    }
    {
        Imf::MultiPartOutputFile file(dir.path("parts.exr").c_str(), headers.data(), int(headers.size()));
        std::vector<float> zeros(4, 0.f);
        for (int i = 0; i < 2; ++i) {
            Imf::OutputPart part(file, i);
            Imf::FrameBuffer frame;
            frame.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(zeros.data()), sizeof(float), 2 * sizeof(float)));
            part.setFrameBuffer(frame);
            part.writePixels(2);
        }
    }
    std::string msg = errorOf([&] { readImage(dir.path("parts.exr")); });
    EXPECT_NE(msg.find("several images"), std::string::npos) << msg;
    {
        Imf::Header header(2, 2);
        header.setType(Imf::DEEPSCANLINE);
        header.compression() = Imf::ZIPS_COMPRESSION;
        header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
        Imf::DeepScanLineOutputFile file(dir.path("deep.exr").c_str(), header);
    }
    msg = errorOf([&] { readImage(dir.path("deep.exr")); });
    EXPECT_NE(msg.find("deep image"), std::string::npos) << msg;
}

TEST(Image, ExrDataWindowBeyondTheLimitIsRefusedFromTheHeader) {
    test::ScratchDir dir("image");
    // Headers whose data windows exceed a side (20000 x 1) or the pixel count (16000 x 5000);
    // the files hold no such pixels: refused from the header, before any line is read.
    Imf::Header::setMaxImageSize(0, 0);  // no limit while writing them; readImage sets its own
    const auto header = [&](const std::string& name, int w, int h) {
        Imf::Header hd(Imath::Box2i({0, 0}, {w - 1, h - 1}), Imath::Box2i({0, 0}, {w - 1, h - 1}));
        hd.channels().insert("R", Imf::Channel(Imf::HALF));
        Imf::OutputFile file(dir.path(name).c_str(), hd);  // closed before any line is written
    };
    header("wide.exr", 20000, 1);
    header("many.exr", 16000, 5000);
    std::string msg = errorOf([&] { readImage(dir.path("wide.exr")); });
    EXPECT_NE(msg.find("wide.exr"), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::to_string(kMaxImageSide)), std::string::npos) << msg;  // OpenEXR's own limit, set by vdbsplat
    msg = errorOf([&] { readImage(dir.path("many.exr")); });
    EXPECT_NE(msg.find("many.exr: image is 16000x5000"), std::string::npos) << msg;
}

TEST(Image, SixteenBitAndAlphaPngsAreDecodedToLinearPremultiplied) {
    test::ScratchDir dir("image");
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = 2, png.height = 1;
    png.format = PNG_FORMAT_RGBA;
    const png_byte rgba[8] = {255, 128, 0, 255, 255, 255, 255, 51};
    ASSERT_TRUE(png_image_write_to_file(&png, dir.path("a8.png").c_str(), 0, rgba, 0, nullptr)) << png.message;
    const Image a8 = readImage(dir.path("a8.png"));
    EXPECT_FLOAT_EQ(a8.at(0, 0).y, srgbToLinear(128 / 255.0f));
    EXPECT_FLOAT_EQ(a8.at(1, 0).x, 0.2f);  // white at alpha 0.2, premultiplied
    EXPECT_FLOAT_EQ(a8.at(1, 0).w, 0.2f);
    png_image png16{};
    png16.version = PNG_IMAGE_VERSION;
    png16.width = 1, png16.height = 1;
    png16.format = PNG_FORMAT_LINEAR_RGB;  // written as a 16-bit file
    const png_uint_16 rgb16[3] = {65535, 16384, 0};
    ASSERT_TRUE(png_image_write_to_file(&png16, dir.path("a16.png").c_str(), 0, rgb16, 0, nullptr)) << png16.message;
    const Image a16 = readImage(dir.path("a16.png"));
    EXPECT_NEAR(a16.at(0, 0).x, 1.0f, 1e-4f);
    EXPECT_NEAR(a16.at(0, 0).y, 0.25f, 2e-3f);  // linear, through libpng's 16-bit path
    EXPECT_EQ(a16.at(0, 0).w, 1.0f);
}

TEST(Image, WritesThroughASymbolicLinkAndRefusesAFifo) {
    test::ScratchDir dir("image");
    fs::create_symlink("target.exr", dir.path("link.exr"));
    writeImage(dir.path("link.exr"), ramp(3, 3));
    EXPECT_TRUE(fs::is_symlink(dir.path("link.exr")));
    EXPECT_EQ(readImage(dir.path("target.exr")).width, 3);
    ASSERT_EQ(::mkfifo(dir.path("fifo.png").c_str(), 0644), 0);
    const std::string msg = errorOf([&] { writeImage(dir.path("fifo.png"), ramp(3, 3)); });
    EXPECT_NE(msg.find("fifo.png"), std::string::npos) << msg;
    EXPECT_TRUE(fs::is_fifo(dir.path("fifo.png")));
    test::expectNoTemporaries(dir.dir());
}

// A new Image is transparent everywhere, also where its memory was another image's a moment ago:
// small images (calloc) and large ones (mapped pages, ZeroedAllocator::kMapBytes and more), one
// after another as bench and animate make them, each written whole before it goes.
TEST(Image, EveryNewImageIsTransparentAlsoAfterAnotherWasWritten) {
    for (const int side : {16, 300, 1024}) {
        for (int round = 0; round < 3; ++round) {
            Image image(side, side);
            ASSERT_EQ(image.pixels.size(), size_t(side) * size_t(side));
            size_t nonZero = 0;
            for (const glm::vec4& p : image.pixels) nonZero += p != glm::vec4(0.f);
            EXPECT_EQ(nonZero, 0u) << side << "² image, round " << round;
            std::fill(image.pixels.begin(), image.pixels.end(), glm::vec4(0.25f, 0.5f, 0.75f, 1.f));
        }
    }
    // A copy is the copy, not zeros (the allocator's construct leaves only default-constructed
    // elements alone).
    Image a(512, 512);
    a.at(7, 9) = glm::vec4(1.f, 2.f, 3.f, 4.f);
    const Image b = a;
    EXPECT_EQ(b.at(7, 9), glm::vec4(1.f, 2.f, 3.f, 4.f));
}

}  // namespace
}  // namespace vdbsplat
