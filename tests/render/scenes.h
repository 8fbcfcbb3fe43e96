// tests/render/scenes.h — small in-memory scenes with known answers for render tests.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern
#include <openvdb/math/Transform.h>

#include "render/render.h"
#include "render/settings.h"
#include "volume/generate.h"
#include "volume/grid.h"
#include "volume/transfer_function.h"

namespace vdbsplat::test {

/// A table that classifies every value in [0, 1] as extinction @p sigma (per voxel length), colour @p color.
inline ClassificationTable constantTable(float sigma, glm::vec3 color = glm::vec3(1.f)) {
    return ClassificationTable(std::vector<Classified>(ClassificationTable::kSize, Classified{color, sigma}), 0.f, 1.f);
}

/// A table σ(v) = @p sigmaMax · v (grey colour v), so values select the extinction.
inline ClassificationTable rampTable(float sigmaMax) {
    std::vector<Classified> e(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        const float v = float(i) / (ClassificationTable::kSize - 1);
        e[i] = Classified{glm::vec3(v), sigmaMax * v};
    }
    return ClassificationTable(std::move(e), 0.f, 1.f);
}

/// Active voxels of value @p value over the index box [lo, hi] (inclusive), voxel size @p h.
inline Volume boxVolume(openvdb::Coord lo, openvdb::Coord hi, float value = 1.f, double h = 1.0) {
    initOpenVdb();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
    grid->denseFill(openvdb::CoordBBox(lo, hi), value, true);
    grid->tree().voxelizeActiveTiles();
    return makeVolume(grid, "test-box");
}

/// Settings of @p mode at the standard framing, @p distance times the framing distance,
/// @p size² pixels, a reference of 9 rays per pixel (3×3 jittered).
inline RenderSettings settingsFor(RenderMode mode, double distance = 1.0, int size = 96) {
    RenderSettings s;
    s.mode = mode;
    s.camera.width = s.camera.height = size;
    s.camera.distance = distance;
    s.spp = 9;
    return s;
}

/// Renders @p v (the stats into @p out when given).
inline Image renderWith(const Volume& v, const TransferFunction& tf, const RenderSettings& s, RenderStats* out = nullptr) {
    RenderStats stats;
    Image image = render(v, tf, s, stats);
    if (out) *out = stats;
    return image;
}

/// Constant colour @p rgb and extinction @p sigma (per voxel length) for every value.
inline TransferFunction constantTf(float sigma, glm::vec3 rgb = glm::vec3(1.f)) {
    return TransferFunction::fromPoints("constant", {{0.f, rgb}, {1.f, rgb}}, {{0.f, sigma}, {1.f, sigma}});
}

/// The Marschner–Lobb test signal at 41³, built once.
inline const Volume& marschnerLobb() {
    static const Volume v = makeVolume(makeMarschnerLobb(41), "marschner-lobb-41");
    return v;
}

}  // namespace vdbsplat::test
