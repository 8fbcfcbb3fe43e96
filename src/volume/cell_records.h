// volume/cell_records.h — level-of-detail cells as stream records, vectorised.
// Owns: CellFrame (a block's cells' common geometry), CellLanes (up to 16 cells' moments,
// structure of arrays, and what becomes of them), and cellRecords, which turns each cell's
// moments (DESIGN §8.2) into its record: the σ-weighted centroid in view space, its distance,
// the σ-weighted colour, the spread it adds to the point filter beyond a full cell's own
// second moment (projected through the Jacobian of the perspective map at the centroid, EWA
// 2001 eq. 25) and its depth spread. Google Highway, runtime dispatch; cellRecordsScalar is the
// oracle, and the vector form equals it bit for bit: the same float operations in glm's order
// (mat3 · vec3 and vec3 · mat3 left to right, dot (x + y) + z, vec3 / s per component), no
// fused multiply-adds.
#pragma once
#include <glm/glm.hpp>

namespace vdbsplat {

/// @brief What every cell of one block at one level shares.
struct CellFrame {
    glm::vec3 origin{0.f};    ///< the block's first cell's centre in view space
    glm::mat3 toView{1.f};    ///< index offsets → view offsets (the linear part of index → view)
    float focal = 1.f;        ///< f (px)
    float fullMoment = 0.f;   ///< a full cell's own second moment per index axis, (n² − 1)/12
    bool depthSpread = false; ///< compute CellLanes::depthSpread
};

/// @brief Up to kMax cells, structure of arrays, 64-byte aligned: the moments in (CellMoments
/// about each cell's centre, and the cell's centre offset from the frame's origin in index units),
/// the record's geometry and colour out.
struct CellLanes {
    static constexpr int kMax = 16;
    // In.
    alignas(64) float m[kMax];                                     ///< Σσ (> 0)
    alignas(64) float er[kMax], eg[kMax], eb[kMax];                ///< Σσ·c
    alignas(64) float fx[kMax], fy[kMax], fz[kMax];                ///< Σσ·d
    alignas(64) float xx[kMax], yy[kMax], zz[kMax], xy[kMax], xz[kMax], yz[kMax];  ///< Σσ·d dᵀ
    alignas(64) float px[kMax], py[kMax], pz[kMax];                ///< the cell's centre − the first's (index)
    // Out.
    alignas(64) float vx[kMax], vy[kMax], vz[kMax];  ///< the centroid in view space
    alignas(64) float distance[kMax];                ///< |v|
    alignas(64) float r[kMax], g[kMax], b[kMax];     ///< Σσ·c / Σσ
    alignas(64) float spread[kMax];                  ///< px², beyond a full cell's own (≥ 0)
    alignas(64) float depthSpread[kMax];             ///< world², along the view ray (≥ 0; frame.depthSpread only)
};

/// @brief The records of cells [0, @p n) of @p lanes (n ≤ kMax), vectorised.
void cellRecords(const CellFrame& frame, CellLanes& lanes, int n);
/// @brief The same, one cell at a time (the oracle).
void cellRecordsScalar(const CellFrame& frame, CellLanes& lanes, int n);

}  // namespace vdbsplat
