// render/forward_buffers.cpp — see forward_buffers.h.
#include "render/forward_buffers.h"

#include <utility>

namespace vdbsplat {

Image ForwardBuffers::takeImage(int width, int height) {
    const size_t pixels = size_t(width) * size_t(height);
    if (spare_.pixels.capacity() < pixels) {
        spare_ = Image();  // too small: freed, and a zeroed image of the size instead
        return Image(width, height);
    }
    Image image = std::move(spare_);
    spare_ = Image();
    image.width = width, image.height = height;
    image.pixels.resize(pixels);  // within its capacity: no allocation (ZeroedAllocator leaves the values)
    return image;
}

}  // namespace vdbsplat
