// tests/fuzz/fuzz_camera_path.cpp — libFuzzer target: `animate --path` keyframe files
// (animation/camera_path.h) through parseKeyframes, then the frame times and the
// interpolated cameras a render would get (render validates those cameras itself). Every
// input must end in valid keys or a vdbsplat::Error; a crash, hang or sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "animation/camera_path.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace vdbsplat;
    try {
        const auto keys = animation::parseKeyframes(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json",
                                                    glm::dvec3(0, 1, 0), 30.0);
        for (const double t : animation::uniformTimes(keys, 7)) (void)animation::interpolate(keys, t);
        (void)animation::timesAtRate(keys, 24.0);
    } catch (const Error&) {
    }
    return 0;
}
