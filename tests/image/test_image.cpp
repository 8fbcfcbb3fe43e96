// tests/image/test_image.cpp — image/image.h: PNG/EXR round trips, and the input checks of
// readImage (volume, oversized and truncated files refused before any pixel is read, issue
// 12) and the output rules of writeImage (through symbolic links, never over a FIFO).
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <filesystem>

#include <sys/stat.h>

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

// OpenImageIO reads a .vdb as a volume image (depth > 1): readImage ignored the depth and
// wrote depth times past its buffer.
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

// compare reads PNG and EXR only, chosen by content: OpenImageIO's other readers (its
// OpenVDB plugin among them) are never tried on a file that claims to be an image.
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

}  // namespace
}  // namespace vdbsplat
