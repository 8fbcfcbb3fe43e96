// image/image.cpp — PNG/EXR output through OpenImageIO, atomic via rename (through a
// symbolic link to its target; never over a device node), and the bounded, checked input
// of `compare` (a PNG or EXR by content, one flat 2D image, bounded in size, checked
// before any pixel is read).
#include "image/image.h"

#include <OpenImageIO/imageio.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <unistd.h>

#include "util/atomic_file.h"
#include "util/error.h"

namespace vdbsplat {

namespace {
std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

/// OpenImageIO's messages name the temporary file; the user's path replaces it.
std::string renamed(std::string message, const std::string& tmp, const std::string& path) {
    for (size_t at = message.find(tmp); at != std::string::npos; at = message.find(tmp, at + path.size()))
        message.replace(at, tmp.size(), path);
    for (char& c : message)
        if (c == '\n' || c == '\r') c = ' ';
    return message;
}

/// Writes @p data to the file @p tmp; errors name @p path (the user's output), not @p tmp.
void writeWith(const std::string& tmp, const std::string& path, const std::string& format,
               const OIIO::ImageSpec& spec, const void* data) {
    auto out = OIIO::ImageOutput::create(format);
    if (!out) throw Error(path + ": cannot create a " + format + " writer: " + renamed(OIIO::geterror(), tmp, path));
    if (!out->open(tmp, spec)) throw Error(path + ": cannot open for writing: " + renamed(out->geterror(), tmp, path));
    const bool ok = out->write_image(spec.format, data);
    const bool closed = out->close();
    if (!ok || !closed) throw Error(path + ": write failed: " + renamed(out->geterror(), tmp, path));
}

std::string oneLineText(std::string s);

/// Refuses what `compare` cannot treat as one flat image, before any pixel is read.
void checkInputSpec(OIIO::ImageInput& in, const OIIO::ImageSpec& spec, const std::string& path) {
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) throw Error(path + ": empty image");
    if (spec.depth > 1)
        throw Error(path + ": is a volume image (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                    "x" + std::to_string(spec.depth) + "), not a 2D PNG or EXR");
    if (spec.deep) throw Error(path + ": is a deep image; only flat PNG or EXR images can be compared");
    if (spec.width > kMaxImageSide || spec.height > kMaxImageSide)
        throw Error(path + ": image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                    ", larger than the " + std::to_string(kMaxImageSide) + " pixels per side vdbsplat reads");
    if (uint64_t(spec.width) * uint64_t(spec.height) > kMaxImagePixels)
        throw Error(path + ": image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                    ", more than the " + std::to_string(kMaxImagePixels) + " pixels (8192x8192) vdbsplat reads");
    if (spec.nchannels > 64) throw Error(path + ": image has " + std::to_string(spec.nchannels) + " channels");
    if (in.seek_subimage(1, 0)) throw Error(path + ": holds several images (subimages); expected one");
    (void)in.geterror();  // the failed seek's message
    if (!in.seek_subimage(0, 0)) throw Error(path + ": cannot read image: " + oneLineText(in.geterror()));
}

/// OpenImageIO's message on one line.
std::string oneLineText(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

/// The OpenImageIO reader for @p path chosen by its first bytes: "png", "openexr", or ""
/// for anything else. compare reads PNG and EXR only: left to itself OpenImageIO tries every
/// plugin it has (its OpenVDB plugin read a damaged .vdb named .png in-process).
std::string readerByContent(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return "";
    unsigned char sig[8] = {};
    const size_t n = std::fread(sig, 1, sizeof sig, f);
    std::fclose(f);
    if (n == sizeof sig && png_sig_cmp(sig, 0, sizeof sig) == 0) return "png";
    if (n >= 4 && sig[0] == 0x76 && sig[1] == 0x2f && sig[2] == 0x31 && sig[3] == 0x01) return "openexr";
    return "";
}

/// True when @p path starts with OpenVDB's magic number (int64 0x56444220, little-endian).
bool isVdbFile(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    unsigned char sig[8] = {};
    const size_t n = std::fread(sig, 1, sizeof sig, f);
    std::fclose(f);
    static const unsigned char kMagic[8] = {0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0};
    return n == sizeof sig && std::equal(sig, sig + 8, kMagic);
}

/// Decodes a PNG once through libpng's simplified API, which reports errors and warnings
/// in png_image::message instead of printing them: OpenImageIO's PNG reader lets libpng's
/// default handler print "libpng error: …" on stderr before it returns its own error, so a
/// damaged PNG must be caught here, quietly. Checks the size limits from the header first.
void validatePng(const std::string& path) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    const auto failed = [&](const std::string& what) {
        const std::string message = image.message[0] ? std::string(image.message) : "unknown libpng error";
        png_image_free(&image);
        return Error(path + ": " + what + ": " + oneLineText(message));
    };
    if (!png_image_begin_read_from_file(&image, path.c_str())) throw failed("cannot read PNG");
    const uint32_t w = image.width, h = image.height;
    if (w > uint32_t(kMaxImageSide) || h > uint32_t(kMaxImageSide) || uint64_t(w) * h > kMaxImagePixels) {
        png_image_free(&image);
        throw Error(path + ": image is " + std::to_string(w) + "x" + std::to_string(h) + ", more than the " +
                    std::to_string(kMaxImageSide) + " pixels per side or " + std::to_string(kMaxImagePixels) +
                    " pixels (8192x8192) vdbsplat reads");
    }
    image.format = PNG_FORMAT_RGBA;
    std::vector<png_byte> pixels(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) throw failed("cannot decode PNG");
    png_image_free(&image);
}

/// Keeps the codecs under OpenImageIO from printing on their own: their messages must reach
/// vdbsplat (through geterror() or validatePng) and become the one error line.
void quietImageLibraries(const std::string& path) {
    if (readerByContent(path) == "png") validatePng(path);
}

/// Opens @p path with the PNG or EXR reader its content calls for; anything else is refused.
std::unique_ptr<OIIO::ImageInput> openPngOrExr(const std::string& path) {
    const std::string reader = readerByContent(path);
    if (reader.empty()) {
        if (isVdbFile(path)) throw Error(path + ": is a VDB file (a volume image), not a 2D PNG or EXR");
        throw Error(path + ": not a PNG or EXR image (unrecognised content)");
    }
    quietImageLibraries(path);
    auto in = OIIO::ImageInput::create(reader);
    OIIO::ImageSpec spec;
    if (!in || !in->open(path, spec))
        throw Error(path + ": cannot read image: " + oneLineText(in ? in->geterror() : OIIO::geterror()));
    return in;
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

void writeImage(const std::string& path, const Image& image, const std::map<std::string, std::string>& metadata) {
    checkImagePath(path);
    const std::string ext = extensionOf(path);
    const std::string target = resolveOutputPath(path);
    // Same folder so the rename is atomic; the extension stays last so OIIO knows the format.
    const std::string tmp = temporaryPathFor(target, ext);
    try {
        if (ext == ".png") {
            OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
            std::vector<unsigned char> bytes(size_t(image.width) * image.height * 3);
            for (size_t i = 0; i < image.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c)
                    bytes[3 * i + c] = static_cast<unsigned char>(std::lround(255.0f * linearToSrgb(image.pixels[i][c])));
            writeWith(tmp, path, "png", spec, bytes.data());
        } else {
            OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
            for (const auto& [key, value] : metadata) spec.attribute("vdbsplat:" + key, value);
            spec.attribute("compression", "zip");
            writeWith(tmp, path, "openexr", spec, image.pixels.data());
        }
        renameIntoPlace(tmp, target, path);
    } catch (...) {
        std::remove(tmp.c_str());
        throw;
    }
}

Image readImage(const std::string& path) {
    const std::unique_ptr<OIIO::ImageInput> in = openPngOrExr(path);
    const OIIO::ImageSpec spec = in->spec();
    checkInputSpec(*in, spec, path);
    const int nc = spec.nchannels;
    std::vector<float> data(size_t(spec.width) * spec.height * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, data.data())) throw Error(path + ": cannot decode: " + oneLineText(in->geterror()));
    const bool srgb = std::string(in->format_name()) != "openexr";  // by content, not by name
    Image image(spec.width, spec.height);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        glm::vec4 p(0.0f, 0.0f, 0.0f, 1.0f);
        for (int c = 0; c < std::min(nc, 4); ++c) p[c] = data[i * nc + c];
        if (nc == 1) p = glm::vec4(p.x, p.x, p.x, 1.0f);
        if (srgb)
            for (int c = 0; c < 3; ++c) p[c] = srgbToLinear(p[c]);
        image.pixels[i] = p;
    }
    return image;
}

}  // namespace vdbsplat
