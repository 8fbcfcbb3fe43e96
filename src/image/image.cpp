// image/image.cpp — PNG/EXR output through OpenImageIO, atomic via rename.
#include "image/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "util/error.h"

namespace vdbsplat {

namespace {
std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

void writeWith(const std::string& path, const std::string& format, const OIIO::ImageSpec& spec, const void* data) {
    auto out = OIIO::ImageOutput::create(format);
    if (!out) throw Error(path + ": cannot create a " + format + " writer: " + OIIO::geterror());
    if (!out->open(path, spec)) throw Error(path + ": cannot open for writing: " + out->geterror());
    const bool ok = out->write_image(spec.format, data);
    const bool closed = out->close();
    if (!ok || !closed) throw Error(path + ": write failed: " + out->geterror());
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
    if (!dir.empty() && !std::filesystem::is_directory(dir)) throw Error(path + ": folder does not exist");
}

void writeImage(const std::string& path, const Image& image, const std::map<std::string, std::string>& metadata) {
    checkImagePath(path);
    const std::string ext = extensionOf(path);
    // Same folder so the rename is atomic; the extension stays last so OIIO knows the format.
    const std::string tmp = path + ".tmp" + std::to_string(::getpid()) + ext;
    try {
        if (ext == ".png") {
            OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
            std::vector<unsigned char> bytes(size_t(image.width) * image.height * 3);
            for (size_t i = 0; i < image.pixels.size(); ++i)
                for (int c = 0; c < 3; ++c)
                    bytes[3 * i + c] = static_cast<unsigned char>(std::lround(255.0f * linearToSrgb(image.pixels[i][c])));
            writeWith(tmp, "png", spec, bytes.data());
        } else {
            OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
            for (const auto& [key, value] : metadata) spec.attribute("vdbsplat:" + key, value);
            spec.attribute("compression", "zip");
            writeWith(tmp, "openexr", spec, image.pixels.data());
        }
        std::filesystem::rename(tmp, path);
    } catch (const std::filesystem::filesystem_error& e) {
        std::remove(tmp.c_str());
        throw Error(path + ": cannot rename temporary file into place: " + e.code().message());
    } catch (...) {
        std::remove(tmp.c_str());
        throw;
    }
}

Image readImage(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) throw Error(path + ": empty image");
    const int nc = spec.nchannels;
    std::vector<float> data(size_t(spec.width) * spec.height * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, data.data())) throw Error(path + ": cannot decode: " + in->geterror());
    const bool srgb = extensionOf(path) != ".exr";
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
