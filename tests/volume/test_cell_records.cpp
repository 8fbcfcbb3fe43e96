// tests/volume/test_cell_records.cpp — volume/cell_records.h: the vectorised cell records equal the
// one-cell-at-a-time oracle bit for bit on every SIMD target, and the oracle is the moment
// matching it claims to be (centroid, colour, projected spread) against sums over explicit voxels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "support/targets.h"
#include "volume/cell_records.h"

namespace vdbsplat {
namespace {

uint32_t gState = 1;
float rnd() {
    gState = gState * 1664525u + 1013904223u;
    return float(gState >> 8) / float(1 << 24);
}

/// A frame off every axis, some 200–900 units in front of the eye.
CellFrame randomFrame(bool depthSpread) {
    CellFrame f;
    f.origin = glm::vec3(-60.f + 120.f * rnd(), -60.f + 120.f * rnd(), 200.f + 700.f * rnd());
    const float a = 6.283f * rnd(), b = 1.2f * rnd();
    const glm::mat3 spin(glm::vec3(std::cos(a), std::sin(a), 0.f), glm::vec3(-std::sin(a), std::cos(a), 0.f), glm::vec3(0.f, 0.f, 1.f));
    const glm::mat3 tilt(glm::vec3(1.f, 0.f, 0.f), glm::vec3(0.f, std::cos(b), std::sin(b)), glm::vec3(0.f, -std::sin(b), std::cos(b)));
    f.toView = tilt * spin * (0.5f + rnd());
    f.focal = 200.f + 800.f * rnd();
    const int side = 1 << (1 + int(3.f * rnd()));
    f.fullMoment = (float(side) * float(side) - 1.f) / 12.f;
    f.depthSpread = depthSpread;
    return f;
}

/// Cell @p l of @p lanes: the moments of a few random voxels about a cell centre of a random cell.
void randomCell(CellLanes& L, int l) {
    float m = 0.f, s[13] = {};
    const int voxels = 1 + int(20.f * rnd());
    for (int v = 0; v < voxels; ++v) {
        const float sigma = 0.01f + rnd(), dx = -3.5f + 7.f * rnd(), dy = -3.5f + 7.f * rnd(), dz = -3.5f + 7.f * rnd();
        m += sigma;
        const float c[3] = {rnd(), rnd(), rnd()};
        for (int k = 0; k < 3; ++k) s[k] += sigma * c[k];
        s[3] += sigma * dx, s[4] += sigma * dy, s[5] += sigma * dz;
        s[6] += sigma * dx * dx, s[7] += sigma * dy * dy, s[8] += sigma * dz * dz;
        s[9] += sigma * dx * dy, s[10] += sigma * dx * dz, s[11] += sigma * dy * dz;
    }
    L.m[l] = m;
    L.er[l] = s[0], L.eg[l] = s[1], L.eb[l] = s[2], L.fx[l] = s[3], L.fy[l] = s[4], L.fz[l] = s[5];
    L.xx[l] = s[6], L.yy[l] = s[7], L.zz[l] = s[8], L.xy[l] = s[9], L.xz[l] = s[10], L.yz[l] = s[11];
    L.px[l] = float(int(8.f * rnd())), L.py[l] = float(int(8.f * rnd())), L.pz[l] = float(int(8.f * rnd()));
}

std::vector<float> outputs(const CellLanes& L, int n, bool depthSpread) {
    std::vector<float> o;
    for (int l = 0; l < n; ++l) {
        o.insert(o.end(), {L.vx[l], L.vy[l], L.vz[l], L.distance[l], L.r[l], L.g[l], L.b[l], L.spread[l]});
        if (depthSpread) o.push_back(L.depthSpread[l]);
    }
    return o;
}

TEST(CellRecords, VectorEqualsTheScalarOracleOnEveryTarget) {
    test::forEachTarget([] {
        gState = 11;
        size_t spread = 0;
        for (int trial = 0; trial < 200; ++trial) {
            const bool depth = trial % 2 == 1;
            const CellFrame frame = randomFrame(depth);
            const int n = 1 + trial % CellLanes::kMax;  // partial batches too
            CellLanes vec, ref;
            for (int l = 0; l < n; ++l) randomCell(vec, l);
            ref = vec;
            cellRecords(frame, vec, n);
            cellRecordsScalar(frame, ref, n);
            ASSERT_EQ(outputs(vec, n, depth), outputs(ref, n, depth)) << "trial " << trial;
            for (int l = 0; l < n; ++l) spread += ref.spread[l] > 0.f ? 1 : 0;
        }
        EXPECT_GT(spread, 100u);  // the spread beyond a full cell's is exercised, not always 0
    });
}

// The oracle against its definition, in double: centroid A·(p + Σσd/Σσ) + origin, colour Σσc/Σσ,
// and spread ½·Σ_rows (jA)ᵀ Σ (jA) − ½·full·|jA|², Σ the covariance about the centroid.
TEST(CellRecords, OracleIsTheMomentMatch) {
    gState = 5;
    for (int trial = 0; trial < 50; ++trial) {
        const CellFrame frame = randomFrame(true);
        CellLanes L;
        randomCell(L, 0);
        cellRecordsScalar(frame, L, 1);
        const double m = L.m[0];
        const glm::dvec3 mu(L.fx[0] / m, L.fy[0] / m, L.fz[0] / m);
        const glm::dmat3 A(frame.toView);
        const glm::dvec3 v = glm::dvec3(frame.origin) + A * (glm::dvec3(L.px[0], L.py[0], L.pz[0]) + mu);
        EXPECT_NEAR(L.vx[0], v.x, 1e-4 * glm::length(v));
        EXPECT_NEAR(L.vz[0], v.z, 1e-4 * glm::length(v));
        EXPECT_NEAR(L.distance[0], glm::length(v), 1e-4 * glm::length(v));
        EXPECT_NEAR(L.g[0], L.eg[0] / m, 1e-5);
        glm::dmat3 cov;
        const double s[6] = {L.xx[0] / m, L.yy[0] / m, L.zz[0] / m, L.xy[0] / m, L.xz[0] / m, L.yz[0] / m};
        cov[0][0] = s[0] - mu.x * mu.x, cov[1][1] = s[1] - mu.y * mu.y, cov[2][2] = s[2] - mu.z * mu.z;
        cov[0][1] = cov[1][0] = s[3] - mu.x * mu.y, cov[0][2] = cov[2][0] = s[4] - mu.x * mu.z;
        cov[1][2] = cov[2][1] = s[5] - mu.y * mu.z;
        const double fz = frame.focal / v.z;
        const glm::dvec3 ux = glm::dvec3(fz, 0.0, -fz * v.x / v.z) * A, uy = glm::dvec3(0.0, fz, -fz * v.y / v.z) * A;
        const double spread = 0.5 * (glm::dot(ux, cov * ux) + glm::dot(uy, cov * uy)) -
                              0.5 * frame.fullMoment * (glm::dot(ux, ux) + glm::dot(uy, uy));
        const double scale = 0.5 * (glm::dot(ux, ux) + glm::dot(uy, uy));  // px² per index unit²
        EXPECT_NEAR(L.spread[0], std::max(spread, 0.0), 1e-3 * scale) << "trial " << trial;
        const glm::dvec3 uz = (v / glm::length(v)) * A;
        EXPECT_NEAR(L.depthSpread[0], std::max(glm::dot(uz, cov * uz), 0.0), 1e-3 * glm::dot(uz, uz));
    }
}

}  // namespace
}  // namespace vdbsplat
