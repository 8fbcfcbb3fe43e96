// footprint/tables.h — the pre-integrated lookup tables of the splat path (DESIGN §3).
// Owns: the 1D footprint table F(d²) (line integral of the normalised kernel at
// normalised ray–centre distance d, d = 1 at R) and the 2D reindex table
// d²(i², α) for α ∈ [0°, 15°] (Yuan et al. 2003 §4, formula corrected in
// reindex.h), their inline linear/bilinear lookups for the per-pixel hot loop,
// and their versioned files in tables/ (text header + float32 payload + FNV-1a
// checksum): generate (deterministic), save, load + verify, compare byte for byte.
//
// No global state: the renderer holds one `Tables` value, from loadOrBuildTables().
#pragma once
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "footprint/footprint_poly.h"
#include "util/fnv1a.h"  // fnv1a64: the payload checksum
#include "footprint/kernel.h"

namespace vdbsplat {

inline constexpr int kTableFormatVersion = 1;              ///< bump when the file layout changes
inline constexpr const char* kFootprintTableFile = "footprint.table";  ///< the standard kernel's
/// @brief The footprint table's file name for @p kernel: kFootprintTableFile for the standard
/// kernel, "footprint-<id>.table" for the others (the reindex table is the kernel's geometry only,
/// one file for all).
std::string footprintTableFile(const KernelShape& kernel);
inline constexpr const char* kReindexTableFile = "reindex.table";

/// @brief F as a function of d² ∈ [0, 1], uniformly sampled in d² (F in voxel units,
/// ∫∫F dA = 1 over the plane in voxel units; Kernel::footprint(d·R)).
class FootprintTable {
public:
    static constexpr int kIntervals = 4096;  ///< 16 KiB of floats: stays in L1/L2

    /// @brief The table built from @p kernel's closed-form footprint (deterministic).
    static FootprintTable build(int intervals = kIntervals, const KernelShape& kernel = KernelShape::standard());

    /// @brief F at normalised squared distance @p d2 (linear interpolation); 0 for
    /// d2 ≥ 1 or NaN, F(0) for d2 < 0.
    float lookupD2(float d2) const {
        if (!(d2 < 1.0f)) return 0.0f;
        const float t = std::max(d2, 0.0f) * scale_;
        const int k = std::min(static_cast<int>(t), last_);
        const float w = t - static_cast<float>(k);
        return v_[k] + w * (v_[k + 1] - v_[k]);
    }
    int intervals() const { return last_ + 1; }
    const std::vector<float>& values() const { return v_; }
    double maxAbsError() const { return maxAbsError_; }  ///< measured against the closed form
    double errorBound() const { return errorBound_; }    ///< stated in the header; tests assert it

    /// @brief Internal: used by build() and the file loader.
    FootprintTable(std::vector<float> values, double maxAbsError, double errorBound);
    FootprintTable() = default;

private:
    std::vector<float> v_;
    float scale_ = 0.0f;
    int last_ = -1;
    double maxAbsError_ = 0.0, errorBound_ = 0.0;
};

/// @brief d²(i², α) = i² / (cos²α + i²·sin²α) (DESIGN §3) on a uniform grid of
/// i² ∈ [0, 1] × α ∈ [0, kAlphaMaxDeg]; outside that α range the formula is evaluated.
class ReindexTable {
public:
    static constexpr int kIntervalsI2 = 128;
    static constexpr int kIntervalsAlpha = 60;    ///< 0.25° steps
    static constexpr double kAlphaMaxDeg = 15.0;  ///< the seed's common range

    /// @brief The table at one α, prepared once per splat; d2() is called per pixel.
    /// Holds pointers into its ReindexTable, which must outlive it.
    struct Row {
        const float* r0 = nullptr;  ///< lower α row; nullptr → evaluate the formula
        const float* r1 = nullptr;  ///< upper α row
        float wAlpha = 0.0f, scale = 0.0f;
        int last = 0;
        float cos2 = 1.0f, sin2 = 0.0f;  ///< for the formula path

        /// @brief d² at squared affine index @p i2 (clamped to [0, 1]; NaN → 1).
        float d2(float i2) const {
            if (!(i2 < 1.0f)) return 1.0f;
            i2 = std::max(i2, 0.0f);
            if (!r0) return i2 / (cos2 + i2 * sin2);
            const float t = i2 * scale;
            const int k = std::min(static_cast<int>(t), last);
            const float w = t - static_cast<float>(k);
            const float lo = r0[k] + w * (r0[k + 1] - r0[k]);
            const float hi = r1[k] + w * (r1[k + 1] - r1[k]);
            return lo + wAlpha * (hi - lo);
        }
    };

    /// @brief The table built from reindex2() (deterministic).
    static ReindexTable build(int intervalsI2 = kIntervalsI2, int intervalsAlpha = kIntervalsAlpha,
                              double alphaMaxDeg = kAlphaMaxDeg);

    /// @brief The row for half cone angle @p alpha (radians): bilinear in the table's
    /// range [0, alphaMax], the closed form outside it (and for NaN/negative α: d² = i²).
    Row row(double alpha) const;
    /// @brief Convenience (slow path): row(alpha).d2(i2).
    float d2(float i2, double alpha) const { return row(alpha).d2(i2); }

    int intervalsI2() const { return nI2_; }
    int intervalsAlpha() const { return nAlpha_; }
    double alphaMaxDeg() const { return alphaMaxDeg_; }
    const std::vector<float>& values() const { return v_; }  ///< α rows, i² fastest
    double maxAbsError() const { return maxAbsError_; }
    double errorBound() const { return errorBound_; }

    /// @brief Internal: used by build() and the file loader.
    ReindexTable(std::vector<float> values, int intervalsI2, int intervalsAlpha, double alphaMaxDeg,
                 double maxAbsError, double errorBound);
    ReindexTable() = default;

private:
    std::vector<float> v_;
    int nI2_ = 0, nAlpha_ = 0;
    double alphaMaxDeg_ = 0.0, alphaMax_ = 0.0;
    double maxAbsError_ = 0.0, errorBound_ = 0.0;
};

/// @brief Both tables (and the vector loop's polynomial fits of their composition, built in
/// memory: footprint_poly.h); the renderer holds one by value and passes it by const reference.
struct Tables {
    FootprintTable footprint;
    ReindexTable reindex;
    FootprintPolynomials poly;
    const KernelShape* kernel = &KernelShape::standard();  ///< the kernel footprint and poly were built for
};

/// @brief Max |lookup − closed form| of @p t over a dense deterministic sampling
/// (16 samples per interval, both ends included); the float lookup path is measured.
double measureFootprintError(const FootprintTable& t, const KernelShape& kernel = KernelShape::standard());
/// @brief Max |d² lookup − reindex2| over 8×8 samples per cell of the α range.
double measureReindexError(const ReindexTable& t);

/// @brief Builds both tables in memory (deterministic, ≈ 50 ms).
Tables buildTables(const KernelShape& kernel = KernelShape::standard());

/// @brief The directory of the shipped tables: VDBSPLAT_SOURCE_DIR "/tables".
std::filesystem::path defaultTablesDir();

/// @brief The exact bytes of a table file (header + payload); what save() writes and
/// `vdbsplat tables --check` compares against.
std::string serializeFootprintTable(const FootprintTable& t, const KernelShape& kernel = KernelShape::standard());
std::string serializeReindexTable(const ReindexTable& t);

/// @brief Parses and verifies a table file's bytes. @p name is used in messages.
/// @throw Error naming @p name: bad magic, wrong format version, wrong table kind, a
/// table built for another kernel (name, s_g or R), bad sizes, truncated or oversized
/// payload, checksum mismatch.
FootprintTable parseFootprintTable(const std::string& bytes, const std::string& name,
                                   const KernelShape& kernel = KernelShape::standard());
ReindexTable parseReindexTable(const std::string& bytes, const std::string& name);

/// @brief Writes footprint.table and reindex.table into @p dir (created if needed).
/// @throw Error naming the file when it cannot be written.
void saveTables(const Tables& tables, const std::filesystem::path& dir);

/// @brief Loads and verifies both files from @p dir.
/// @throw Error naming the file: missing, unreadable, or any parse failure above.
Tables loadTables(const std::filesystem::path& dir, const KernelShape& kernel = KernelShape::standard());

/// @brief The renderer's entry point. For each table: if its file in @p dir is ABSENT,
/// build it in memory (a source tree without tables/ still renders); if it is present,
/// load and verify it and REFUSE (throw) when it is corrupt or from another kernel —
/// a damaged shipped table is never silently replaced.
Tables loadOrBuildTables(const std::filesystem::path& dir = defaultTablesDir(),
                         const KernelShape& kernel = KernelShape::standard());

/// @brief Verifies the files in @p dir (parse + checksum) and that they are byte for byte
/// what buildTables() + serialize produce now. @return a one-line summary per table.
/// @throw Error naming the file and the first differing byte on mismatch.
std::vector<std::string> checkTables(const std::filesystem::path& dir);

}  // namespace vdbsplat
