// composite/point_raster.h — one point's filter over one tile, into the tile's slab sums.
// Owns: PointRaster (a point's set-up filter, PointSetup, clipped to one tile), SlabTile (the
// tile's slab buffer and transmittance, structure of arrays), drawPointVector (Google Highway,
// runtime dispatch: the pixels of a tile row in one vector) and drawPointScalar, the oracle it
// is tested against (PointRaster.VectorLoopEqualsTheScalarLoop: bit for bit).
//
// Per pixel (x, y) of the clipped footprint that is still live (T ≥ ε), with
// dx = (x + ½) − cx, dy = (y + ½) − cy (PointSetup::offset):
//     w   = dx² + dy² < r_s² ? weight(dx²/V) · weight(dy²/V) : 0     (pointFilterWeight)
//     τ   = total · (w · norm)                                      (norm: the sum to 1)
//     slab τ += τ;  slab emission += τ · colour                      (DESIGN §4: summed per slab)
// — the float operations of rasterizePoint and of the compositor's per-tile loop before it, in
// the same order and without contraction, so the same values.
#pragma once
#include <glm/glm.hpp>

#include "composite/slab_profile.h"
#include "composite/tile.h"
#include "pointfilter/point_filter.h"

namespace vdbsplat {

/// @brief One tile's slab buffer (optical depth and σ-weighted emission per channel) and its
/// transmittance: row-major, stride kTileSize (composite/tile.h), 64-byte aligned arrays. eg and eb
/// null: one channel (ColorChannels::Grey), τ and er alone are written.
struct SlabTile {
    float* tau;
    float* er;
    float* eg;  ///< null with eb: one channel
    float* eb;
    const float* T;
    int x0 = 0, y0 = 0;  ///< image coordinates of the tile's first pixel
};

struct PointRaster {
    float cx = 0.f, cy = 0.f;        ///< the point's centre (pixels)
    float invVariance = 0.f;         ///< PointSetup
    float radius2 = 0.f;
    float norm = 0.f;
    float total = 0.f;               ///< Σ_pixels τ
    glm::vec3 color{0.f};
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  ///< the footprint's pixels inside the tile (inclusive)
    float epsilon = 0.f;             ///< pixels with T < epsilon are finished
};

/// @brief Adds the point's deposits to the live pixels of @p tile's slab (vector loop).
void drawPointVector(const PointRaster& p, const SlabTile& tile);

/// @brief The same, one pixel at a time (the oracle).
void drawPointScalar(const PointRaster& p, const SlabTile& tile);

/// @brief --compositing slabs: the point's deposits into several slabs of one tile, slab j taking
/// fraction j of each pixel's τ (@p T, @p x0, @p y0: the tile's transmittance and first pixel).
/// With one target of fraction 1 this is drawPointVector, bit for bit.
void drawPointSlabsVector(const PointRaster& p, const SlabTargets& slabs, const float* T, int x0, int y0);
/// @brief The same, one pixel at a time (the oracle).
void drawPointSlabsScalar(const PointRaster& p, const SlabTargets& slabs, const float* T, int x0, int y0);

}  // namespace vdbsplat
