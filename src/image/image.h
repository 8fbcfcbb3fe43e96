// image/image.h — the output image and its files.
// Owns: Image (linear, premultiplied RGBA float, row-major, y down) and writing
// it as PNG (8-bit, sRGB-encoded, over black; image/png_writer.h) or EXR (float, linear, with
// metadata; OpenEXR), atomically: a temporary file in the same folder, renamed into
// place, so a failure never leaves a partial image; reading PNG or EXR back (`compare`).
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "util/error.h"
#include "util/huge_pages.h"

namespace vdbsplat {

/// Allocates zeroed memory (calloc) and value-initialises elements by leaving them as they are: a
/// vector sized once on this allocator is all zeros without writing them, and a large one is pages
/// the kernel maps as zeros when first touched (a far view's 1024² output image: 16 MB of which
/// the render writes a few rows, and writing the PNG only reads; the writers advise huge pages for
/// what they write, adviseRowsWritten below). Only for vectors sized once, at
/// construction: a vector shrunk and grown again would keep stale elements. @tparam T trivial.
template <class T>
struct ZeroedAllocator {
    using value_type = T;
    ZeroedAllocator() = default;
    template <class U>
    ZeroedAllocator(const ZeroedAllocator<U>&) noexcept {}
    /// Blocks of kMapBytes and more are fresh anonymous pages (huge_pages::map, as the renderer's
    /// window buffers), not calloc'ed: after glibc has freed one such block its dynamic mmap
    /// threshold rises past it, so the next frame's calloc came from the heap and cleared all
    /// 16 MB of a 1024² image (a few per cent of a warm far render: bench, animate, render
    /// --warmup; docs/performance.md, session 28).
    static constexpr size_t kMapBytes = size_t(1) << 20;
    T* allocate(size_t n) {
        if (n > size_t(-1) / sizeof(T)) throw std::bad_alloc();
        if (n * sizeof(T) >= kMapBytes) return static_cast<T*>(huge_pages::map(huge_pages::roundUp(n * sizeof(T))));
        if (void* p = std::calloc(n, sizeof(T))) return static_cast<T*>(p);
        throw std::bad_alloc();
    }
    void deallocate(T* p, size_t n) noexcept {
        if (n * sizeof(T) >= kMapBytes) munmap(p, huge_pages::roundUp(n * sizeof(T)));
        else std::free(p);
    }
    template <class U>
    void construct(U*) noexcept {}  // value-initialisation: the memory is already zero
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <class U>
    bool operator==(const ZeroedAllocator<U>&) const noexcept { return true; }
};

struct Image {
    int width = 0;
    int height = 0;
    /// Premultiplied linear RGBA, index y * width + x; all zero (transparent) when constructed.
    std::vector<glm::vec4, ZeroedAllocator<glm::vec4>> pixels;

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h)) {}
    glm::vec4& at(int x, int y) { return pixels[size_t(y) * width + x]; }
    const glm::vec4& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

/// @brief An image transparent (all zero) outside one rectangle, its data window (OpenEXR's term),
/// and stored as that rectangle alone: what a render cropped to the pixels its volume covers
/// gives (render/hybrid.cpp), and what `render` writes. A far view's 1024² image holds a 110²
/// rectangle; placed into a full Image, each of its rows wrote into a fresh page of its own (200
/// page faults, 1.5–1.9 ms of a 7.7 ms warm far render on this project's hosts; docs/performance.md,
/// session 46). The PNG writer reads the rectangle and writes the rest as zeros without a full
/// image (writeImage below); full() places it where an Image is needed.
struct WindowedImage {
    int width = 0, height = 0;  ///< the whole image
    int x0 = 0, y0 = 0;         ///< the data window's first column and row; its size is data's
    Image data;                 ///< the data window's pixels (empty: all transparent)

    WindowedImage() = default;
    /// All of @p image (the data window is the whole image).
    explicit WindowedImage(Image image) : width(image.width), height(image.height), data(std::move(image)) {}
    /// @p window placed at (@p x0, @p y0) of a @p width × @p height image; it must lie inside it.
    /// @throw Error when it does not.
    WindowedImage(Image window, int x0, int y0, int width, int height);

    /// Pixel (@p x, @p y) of the whole image: the data window's, or zero outside it.
    glm::vec4 at(int x, int y) const {
        const int u = x - x0, v = y - y0;
        return u >= 0 && v >= 0 && u < data.width && v < data.height ? data.at(u, v) : glm::vec4(0.f);
    }
    /// The whole image: the data window placed, zero elsewhere (the data moved where it is the whole).
    Image full() const&;
    Image full() &&;
};

/// @brief Advises huge pages (huge_pages::adviseWritten) for the rows [@p y0, @p y0 + @p rows) of
/// @p image, which the caller is about to write @p columns of each, if that is at least half of
/// each row: a far view's crop writes a few hundred pixels of a 1024-pixel row, and a huge page of
/// those rows would be cleared whole for them (docs/performance.md, session 30). An image under
/// ZeroedAllocator::kMapBytes is calloc'ed: nothing to advise.
inline void adviseRowsWritten(Image& image, int y0, int rows, int columns) {
    const size_t rowBytes = size_t(image.width) * sizeof(glm::vec4);
    if (image.pixels.size() * sizeof(glm::vec4) < ZeroedAllocator<glm::vec4>::kMapBytes || rows <= 0 || 2 * size_t(columns) < size_t(image.width))
        return;
    huge_pages::adviseWritten(image.pixels.data(), size_t(y0) * rowBytes, (size_t(y0) + size_t(rows)) * rowBytes);
}

/// @brief A composited frame where the compositor keeps it (premultiplied radiance and
/// transmittance T per pixel, row-major), read as RGBA with α = 1 − T without copying it into an
/// Image first (a 1024² frame is 16 MB of fresh pages, a few milliseconds of page faults).
struct FrameView {
    const glm::vec3* color = nullptr;
    const float* transmittance = nullptr;
    int width = 0, height = 0;
    glm::vec4 at(int x, int y) const {
        const size_t i = size_t(y) * size_t(width) + size_t(x);
        return glm::vec4(color[i], 1.f - transmittance[i]);
    }
};

/// Largest image side readImage accepts (as render's --size): checked before any pixel is read.
inline constexpr int kMaxImageSide = 16384;
/// Most pixels readImage accepts (8192², about 2 GB while decoding): checked likewise.
inline constexpr uint64_t kMaxImagePixels = uint64_t(1) << 26;

/// @brief sRGB transfer curve of a linear value in [0, 1] (values outside are clamped).
float linearToSrgb(float v);
/// @brief Inverse of linearToSrgb.
float srgbToLinear(float v);
/// @brief The 8-bit code PNG output writes for linear @p v: lround(255·linearToSrgb(v)), by a
/// table of the codes' thresholds (the same code for every float; 0 for NaN).
uint8_t linearToSrgbCode(float v);

/// @brief Writes @p image to @p path (.png or .exr, by extension) atomically.
/// EXR files carry @p metadata as string attributes.
/// @throw Error naming the path on an unknown extension or a write failure.
void writeImage(const std::string& path, const Image& image,
                const std::map<std::string, std::string>& metadata = {});
/// @brief As above, for an image stored as its data window: a PNG is encoded from the window and
/// zeros, the same bytes as writeImage(path, image.full()) (no full image is built); an EXR is
/// written from image.full().
void writeImage(const std::string& path, const WindowedImage& image,
                const std::map<std::string, std::string>& metadata = {});

/// @brief Reads a PNG (sRGB, decoded to linear) or EXR (linear) back into an Image.
/// The format is chosen by content (PNG or EXR only). @throw Error naming the path when it cannot be read, or before reading pixels when
/// it is not one flat 2D image (a volume, deep or multi-image file) or a side exceeds kMaxImageSide.
Image readImage(const std::string& path);

/// @brief Checks that @p path has an extension writeImage supports, its folder exists and it
/// is not a device node or FIFO (before any work is done).
/// @throw Error naming the path otherwise.
void checkImagePath(const std::string& path);

}  // namespace vdbsplat
