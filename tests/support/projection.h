// tests/support/projection.h — shared by the projection and compositor tests (header only): the
// footprint tables built once per test binary, and the camera that frames the box [−8, 8]³.
#pragma once
#include "camera/camera.h"
#include "footprint/tables.h"

namespace vdbsplat::test {

/// @brief The default footprint tables (buildTables()), built on first use and kept.
inline const Tables& sharedTables() {
    static const Tables t = buildTables();
    return t;
}

/// @brief A @p size × @p size camera framing the box [−8, 8]³ (makeCamera's default view).
inline Camera boxCamera(int size) {
    CameraSpec spec;
    spec.width = spec.height = size;
    return makeCamera(spec, glm::dvec3(-8.0), glm::dvec3(8.0));
}

}  // namespace vdbsplat::test
