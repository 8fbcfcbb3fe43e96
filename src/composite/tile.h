// composite/tile.h — the compositor's screen tile, shared by the tile loop and the raster loops.
// Owns: kTileSize, the side of a square tile in pixels, which is also the row stride of a tile's
// pixel arrays (TileBuffers, PointTileBuffers, the slab buffers).
//
// 32 rather than 16 (session 10): a framed view's splats are ~8 px across, and each (splat, tile)
// pair costs a bin entry and a per-tile set-up (the chords, the footprint's polynomial row), so
// larger tiles mean ~1.5 tiles per splat instead of ~2.2 (framed Engine 1.04×, checker box
// 1.04–1.06×, same images). A tile's four float arrays (16 KiB) still fit in L1.
#pragma once

namespace vdbsplat {

inline constexpr int kTileSize = 32;
inline constexpr int kTilePixels = kTileSize * kTileSize;

}  // namespace vdbsplat
