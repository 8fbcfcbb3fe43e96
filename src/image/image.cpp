// image/image.cpp — PNG output (image/png_writer.h: sRGB codes by table, Paeth filter, run-length
// deflate, bands in parallel) and EXR output through OpenEXR, atomic via rename (through a
// symbolic link to its target; never over a device node), and the bounded, checked input of `compare` (a PNG or EXR
// by content, one flat 2D image, bounded in size, checked before any pixel is read). The two
// libraries are used directly, not through OpenImageIO: its 230 shared libraries (codecs,
// OpenCV, GDAL, ...) cost every vdbsplat process about 0.5 s of CPU and 100 MB before main()
// (docs/performance.md).
#include "image/image.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <IlmThread.h>
#include <tbb/global_control.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <unistd.h>

#include "image/png_writer.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"

namespace vdbsplat {

namespace {
std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

/// A library's message naming the user's @p path where it names the temporary @p tmp. (Line
/// breaks and control characters are escaped where every error is printed, cli/main.cpp.)
std::string renamed(std::string message, const std::string& tmp, const std::string& path) {
    for (size_t at = message.find(tmp); at != std::string::npos; at = message.find(tmp, at + path.size()))
        message.replace(at, tmp.size(), path);
    return message;
}

std::string sizeText(int64_t w, int64_t h) { return std::to_string(w) + "x" + std::to_string(h); }

/// Refuses a @p w x @p h image beyond the limits of image.h, before any pixel is read.
void checkImageSize(int64_t w, int64_t h, const std::string& path) {
    if (w < 1 || h < 1) throw Error(path + ": empty image (" + sizeText(w, h) + ")");
    if (w > kMaxImageSide || h > kMaxImageSide)
        throw Error(path + ": image is " + sizeText(w, h) + ", larger than the " + std::to_string(kMaxImageSide) +
                    " pixels per side vdbsplat reads");
    if (uint64_t(w) * uint64_t(h) > kMaxImagePixels)
        throw Error(path + ": image is " + sizeText(w, h) + ", more than the " + std::to_string(kMaxImagePixels) +
                    " pixels (8192x8192) vdbsplat reads");
}

/// The first 8 bytes of @p path (fewer if it is shorter; none if it cannot be opened).
std::vector<unsigned char> signatureOf(const std::string& path) {
    std::vector<unsigned char> sig(8);
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return {};
    sig.resize(std::fread(sig.data(), 1, sig.size(), f));
    std::fclose(f);
    return sig;
}

bool isPng(const std::vector<unsigned char>& sig) {
    return sig.size() == 8 && png_sig_cmp(sig.data(), 0, 8) == 0;
}
bool isExr(const std::vector<unsigned char>& sig) {
    return sig.size() >= 4 && sig[0] == 0x76 && sig[1] == 0x2f && sig[2] == 0x31 && sig[3] == 0x01;
}
/// OpenVDB's magic number (int64 0x56444220, little-endian).
bool isVdb(const std::vector<unsigned char>& sig) {
    static const unsigned char kMagic[8] = {0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0};
    return sig.size() == 8 && std::equal(sig.begin(), sig.end(), kMagic);
}

/// libpng's simplified API reports errors and warnings in png_image::message and never
/// prints them; this frees the image on every path.
struct PngImage {
    png_image image{};
    PngImage() { image.version = PNG_IMAGE_VERSION; }
    ~PngImage() { png_image_free(&image); }
    std::string message() const { return image.message[0] ? std::string(image.message) : "unknown libpng error"; }
};

/// Writes @p bytes to @p tmp (errors name the user's @p path).
void writeFileBytes(const std::string& tmp, const std::string& path, const std::vector<uint8_t>& bytes) {
    std::FILE* file = std::fopen(tmp.c_str(), "wb");
    if (!file) throw Error(path + ": write failed: " + std::strerror(errno));
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size() && std::fflush(file) == 0;
    const int err = errno;
    if (std::fclose(file) != 0 && written) throw Error(path + ": write failed: " + std::strerror(errno));
    if (!written) throw Error(path + ": write failed: " + std::strerror(err));
}

void writePng(const std::string& tmp, const std::string& path, const Image& image) {
    if (image.width < 1 || image.height < 1) throw Error(path + ": write failed: empty image");
    writeFileBytes(tmp, path, encodePng(image));  // image/png_writer.h
}

/// Sets OpenEXR's own header limits (it checks them while reading a header, before it
/// allocates line or tile tables from it) to the bounds of checkImageSize. They are
/// process-wide settings of the library, so they are set again before every read.
void limitOpenExr() {
    Imf::Header::setMaxImageSize(kMaxImageSide, kMaxImageSide);
    Imf::Header::setMaxTileSize(kMaxImageSide, kMaxImageSide);
}

void writeExr(const std::string& tmp, const std::string& path, const Image& image,
              const std::map<std::string, std::string>& metadata) {
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const auto& [key, value] : metadata) header.insert("vdbsplat:" + key, Imf::StringAttribute(value));
        Imf::FrameBuffer frame;
        const char* base = reinterpret_cast<const char*>(image.pixels.data());
        const size_t xStride = sizeof(glm::vec4), yStride = xStride * size_t(image.width);
        const char* names[4] = {"R", "G", "B", "A"};
        for (int c = 0; c < 4; ++c) {
            header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(base) + c * sizeof(float), xStride, yStride));
        }
        // Line blocks compressed on as many threads as TBB may use (--threads): OpenEXR writes
        // them in order, so the file's bytes do not depend on the count; 1.4–1.8× faster on two
        // cores at 1024² (docs/performance.md, session 17).
        const size_t allowed = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
        const int threads = allowed > 1 ? int(std::min<size_t>(allowed, 64)) : 0;  // 0: this thread alone
        if (IlmThread::supportsThreads() && Imf::globalThreadCount() != threads) Imf::setGlobalThreadCount(threads);
        Imf::OutputFile file(tmp.c_str(), header, Imf::globalThreadCount());
        file.setFrameBuffer(frame);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        throw Error(path + ": write failed: " + renamed(e.what(), tmp, path));
    }
}

/// A PNG, decoded to linear premultiplied RGBA: 8-bit files through vdbsplat's own sRGB curve
/// (so a PNG that vdbsplat wrote reads back to the values it encoded), 16-bit files through
/// libpng's linear 16-bit form (premultiplied by libpng).
Image readPng(const std::string& path) {
    PngImage png;
    if (!png_image_begin_read_from_file(&png.image, path.c_str()))
        throw Error(path + ": cannot read PNG: " + png.message());
    checkImageSize(png.image.width, png.image.height, path);
    Image image(static_cast<int>(png.image.width), static_cast<int>(png.image.height));
    if (png.image.format & PNG_FORMAT_FLAG_LINEAR) {
        png.image.format = PNG_FORMAT_LINEAR_RGB_ALPHA;
        std::vector<png_uint_16> data(PNG_IMAGE_SIZE(png.image) / sizeof(png_uint_16));
        if (!png_image_finish_read(&png.image, nullptr, data.data(), 0, nullptr))
            throw Error(path + ": cannot decode PNG: " + png.message());
        for (size_t i = 0; i < image.pixels.size(); ++i)
            image.pixels[i] = glm::vec4(data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]) / 65535.0f;
    } else {
        png.image.format = PNG_FORMAT_RGBA;
        std::vector<png_byte> data(PNG_IMAGE_SIZE(png.image));
        if (!png_image_finish_read(&png.image, nullptr, data.data(), 0, nullptr))
            throw Error(path + ": cannot decode PNG: " + png.message());
        std::array<float, 256> linear;  // the sRGB curve of each 8-bit code, once
        for (int code = 0; code < 256; ++code) linear[code] = srgbToLinear(code / 255.0f);
        for (size_t i = 0; i < image.pixels.size(); ++i) {
            const float alpha = data[4 * i + 3] / 255.0f;
            image.pixels[i] = glm::vec4(linear[data[4 * i]], linear[data[4 * i + 1]], linear[data[4 * i + 2]], 1.0f) * alpha;
        }
    }
    return image;
}

/// The channels an EXR image is read from: R, G, B (and A) if it has them, else Y (and A),
/// else its only channel; one channel is grey. Refuses anything else, naming the channels.
std::vector<std::string> exrChannels(const Imf::ChannelList& channels, const std::string& path) {
    const auto has = [&](const char* name) { return channels.findChannel(name) != nullptr; };
    std::vector<std::string> names;
    if (has("R") && has("G") && has("B")) names = {"R", "G", "B"};
    else if (has("Y")) names = {"Y"};
    else {
        std::string all;
        int count = 0;
        for (auto it = channels.begin(); it != channels.end(); ++it, ++count) all += (count ? ", " : "") + std::string(it.name());
        if (count != 1) throw Error(path + ": EXR image has no R, G, B or Y channels (" + printable(all, 200) + ")");
        return {all};
    }
    if (has("A")) names.push_back("A");
    return names;
}

/// One flat scan-line or tiled EXR part, any pixel type, converted to float by OpenEXR.
Image readExr(const std::string& path) {
    limitOpenExr();
    try {
        Imf::MultiPartInputFile file(path.c_str());
        if (file.parts() != 1) throw Error(path + ": holds several images (" + std::to_string(file.parts()) + " parts); expected one");
        const Imf::Header& header = file.header(0);
        if (header.hasType() && (header.type() == Imf::DEEPSCANLINE || header.type() == Imf::DEEPTILE))
            throw Error(path + ": is a deep image; only flat PNG or EXR images can be compared");
        const Imath::Box2i window = header.dataWindow();
        const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
        checkImageSize(w, h, path);
        const std::vector<std::string> names = exrChannels(header.channels(), path);
        std::vector<float> data(size_t(w) * size_t(h) * names.size());
        Imf::FrameBuffer frame;
        const size_t xStride = sizeof(float) * names.size(), yStride = xStride * size_t(w);
        for (size_t c = 0; c < names.size(); ++c)
            frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, data.data() + c, window, xStride, yStride));
        Imf::InputPart part(file, 0);
        part.setFrameBuffer(frame);
        part.readPixels(window.min.y, window.max.y);
        Image image(static_cast<int>(w), static_cast<int>(h));
        const bool grey = names[0] != "R";
        const bool alpha = names.back() == "A";
        for (size_t i = 0; i < image.pixels.size(); ++i) {
            const float* p = &data[i * names.size()];
            image.pixels[i] = grey ? glm::vec4(p[0], p[0], p[0], alpha ? p[1] : 1.0f)
                                   : glm::vec4(p[0], p[1], p[2], alpha ? p[3] : 1.0f);
        }
        return image;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path + ": cannot read EXR: " + std::string(e.what()));
    }
}
}  // namespace

float linearToSrgb(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgbToLinear(float v) {
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

void checkImagePath(const std::string& path) {
    const std::string ext = extensionOf(path);
    if (ext != ".png" && ext != ".exr") throw Error(path + ": output must end in .png or .exr");
    const auto dir = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) throw Error(path + ": folder does not exist");
    checkRegularOutputPath(path);
}

WindowedImage::WindowedImage(Image window, int x0_, int y0_, int width_, int height_)
    : width(width_), height(height_), x0(x0_), y0(y0_), data(std::move(window)) {
    if (width < 0 || height < 0 || x0 < 0 || y0 < 0 || int64_t(x0) + data.width > width || int64_t(y0) + data.height > height)
        throw Error("image: a " + sizeText(data.width, data.height) + " window at (" + std::to_string(x0) + ", " +
                    std::to_string(y0) + ") does not lie inside a " + sizeText(width, height) + " image");
}

Image WindowedImage::full() const& {
    Image out(width, height);
    if (data.width == 0 || data.height == 0) return out;
    adviseRowsWritten(out, y0, data.height, data.width);
    for (int v = 0; v < data.height; ++v)
        std::copy_n(&data.pixels[size_t(v) * size_t(data.width)], size_t(data.width), &out.at(x0, y0 + v));
    return out;
}

Image WindowedImage::full() && {
    if (x0 == 0 && y0 == 0 && data.width == width && data.height == height) return std::move(data);
    return static_cast<const WindowedImage&>(*this).full();
}

namespace {
/// Checks @p path, then has @p write(tmp, ext) write the file to a temporary beside its target and
/// renames it into place; a failure removes the temporary (nothing partial, nothing clobbered).
template <class Write>
void writeAtomically(const std::string& path, const Write& write) {
    checkImagePath(path);
    const std::string ext = extensionOf(path);
    const std::string target = resolveOutputPath(path);
    const std::string tmp = temporaryPathFor(target, ext);  // same folder: the rename is atomic
    try {
        write(tmp, ext);
        renameIntoPlace(tmp, target, path);
    } catch (...) {
        std::remove(tmp.c_str());
        throw;
    }
}
}  // namespace

void writeImage(const std::string& path, const WindowedImage& image, const std::map<std::string, std::string>& metadata) {
    checkImagePath(path);  // before full() builds an image for a path that would be refused
    if (extensionOf(path) != ".png") return writeImage(path, image.full(), metadata);
    writeAtomically(path, [&](const std::string& tmp, const std::string&) {
        if (image.width < 1 || image.height < 1) throw Error(path + ": write failed: empty image");
        writeFileBytes(tmp, path, encodePng(image));  // from the window and zeros (image/png_writer.h)
    });
}

void writeImage(const std::string& path, const Image& image, const std::map<std::string, std::string>& metadata) {
    writeAtomically(path, [&](const std::string& tmp, const std::string& ext) {
        if (ext == ".png") writePng(tmp, path, image);
        else writeExr(tmp, path, image, metadata);
    });
}

Image readImage(const std::string& path) {
    const std::vector<unsigned char> sig = signatureOf(path);
    if (isPng(sig)) return readPng(path);
    if (isExr(sig)) return readExr(path);
    if (!std::filesystem::exists(path)) throw Error(path + ": cannot read image: no such file");
    if (isVdb(sig)) throw Error(path + ": is a VDB file (a volume image), not a 2D PNG or EXR");
    throw Error(path + ": not a PNG or EXR image (unrecognised content)");
}

}  // namespace vdbsplat
