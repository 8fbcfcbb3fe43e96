// volume/generate.h — procedural test volumes (`vdbsplat generate`).
// Owns: the sparse float grids named "density" (fog volumes, voxel size 1,
// values in [0,1]) that the tests, demos and benchmarks render:
//  - checkerbox:     the 3D Checker Box of Yuan et al. 2003 (every voxel active),
//  - marschner-lobb: the Marschner–Lobb 1994 test signal (f_M = 6, α = 0.25),
//  - sphere:         a smooth fog ball,
//  - cloud:          thresholded fractal value noise with a requested active count,
//  - tubes:          random thin tubes and a few thin sheets (DESIGN §8.3: structures one or
//                    two pixels wide, where filtering optical depth before compositing fails),
//  - explosion:      a fireball: "density" plus a "temperature" grid for emission (docs/emission.md).
// Every grid is built leaf by leaf (8³) in parallel and inserted in a fixed order,
// so the result is identical for any thread count and never densified.
#pragma once
#include "volume/openvdb_extern.h"  // <openvdb/openvdb.h>, grid classes extern

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vdbsplat {

/// Checker box: cells per side (independent of --res, so the pattern scales with it).
inline constexpr int kCheckerCellsPerSide = 10;
/// Checker box: density of the cells whose cell-index sum is even / odd.
inline constexpr float kCheckerDensityEven = 1.0f;
inline constexpr float kCheckerDensityOdd = 0.3f;
/// Marschner–Lobb parameters (the 1994 paper's standard choice).
inline constexpr double kMarschnerLobbFM = 6.0;
inline constexpr double kMarschnerLobbAlpha = 0.25;
/// Upper bound on the active voxels any generator may create (about 8 GB of float leaves).
inline constexpr uint64_t kMaxGeneratedVoxels = 2'000'000'000ull;
/// Largest --res accepted (further limited by kMaxGeneratedVoxels).
inline constexpr int kMaxGenerateRes = 4096;
/// Cloud: promised accuracy of the active count, |count − N| / N, for N ≥ 1000 (measured well below).
inline constexpr double kCloudCountTolerance = 0.02;
/// Default sizes.
inline constexpr int kDefaultCheckerRes = 100, kDefaultMarschnerLobbRes = 41, kDefaultSphereRes = 64;
inline constexpr uint64_t kDefaultCloudActive = 1'000'000, kDefaultCloudSeed = 1;
/// Tubes: the defaults make issue 10's reference volume (14 tubes, radius 0.7–2.5 voxels).
inline constexpr int kDefaultTubesRes = 128, kDefaultTubeCount = 14, kDefaultSheetCount = 2;
inline constexpr double kDefaultTubeRadiusMin = 0.7, kDefaultTubeRadiusMax = 2.5;
/// Explosion: default grid side.
inline constexpr int kDefaultExplosionRes = 96;
/// Tubes: density 1 within the radius, then (1 − (s/w)²)² over a rim of w voxels (C¹), 0 beyond.
inline constexpr double kTubeFalloffVoxels = 1.0;
/// Tubes: radius bounds accepted by --radius-min/--radius-max (voxels), and the most tubes/sheets.
inline constexpr double kMinTubeRadius = 0.1, kMaxTubeRadius = 64.0;
inline constexpr int kMaxTubeCount = 100000;

/// @brief What to generate; unset fields take the kind's default in validate().
struct GenerateOptions {
    std::string kind{};             ///< checkerbox | marschner-lobb | sphere | cloud
    std::optional<int> res{};       ///< grid side in voxels (not for cloud)
    std::optional<uint64_t> active{}; ///< cloud only: target active voxel count
    std::optional<uint64_t> seed{};   ///< cloud and tubes: seed
    std::optional<int> count{};       ///< tubes only: number of tubes
    std::optional<int> sheets{};      ///< tubes only: number of thin sheets
    std::optional<double> radiusMin{}, radiusMax{};  ///< tubes only: radius range (voxels)

    /// @brief Fills in defaults and checks the combination (messages name the flag).
    /// @throw Error for an unknown kind, a flag the kind does not use, or sizes out of bounds.
    void validate();

private:
    void validateTubes();  ///< validate()'s part for 'tubes'
};

/// @brief The names accepted as GenerateOptions::kind, in documentation order.
const std::vector<std::string>& generatorKinds();

/// @brief Generates every grid @p options describe (validated first): one, or for 'explosion'
/// the density and the temperature grid. @throw Error as GenerateOptions::validate.
std::vector<openvdb::FloatGrid::Ptr> generateGrids(GenerateOptions options);

/// @brief Generates the grid described by @p options (validated first; 'explosion': its density).
/// @throw Error as GenerateOptions::validate.
openvdb::FloatGrid::Ptr generateVolume(GenerateOptions options);

/// @brief The 3D Checker Box: res³ voxels at index (0..res-1)³, all active, kCheckerCellsPerSide
/// cells per side; voxel (i,j,k) lies in cell (⌊10i/res⌋, ⌊10j/res⌋, ⌊10k/res⌋) and has
/// kCheckerDensityEven when the cell indices sum to an even number, kCheckerDensityOdd otherwise.
/// @param res side in voxels (validated by GenerateOptions)
openvdb::FloatGrid::Ptr makeCheckerBox(int res);

/// @brief The Marschner–Lobb value at a point of [-1,1]³:
/// ρ = (1 − sin(πz/2) + α(1 + cos(2π f_M cos(π r/2)))) / (2(1 + α)), r = √(x² + y²); in [0,1].
double marschnerLobb(double x, double y, double z);

/// @brief The Marschner–Lobb signal sampled at res³ points of [-1,1]³: index i ↦ −1 + 2i/(res−1); all active.
/// @param res samples per axis (validated by GenerateOptions)
openvdb::FloatGrid::Ptr makeMarschnerLobb(int res);

/// @brief A smooth fog ball: centre c = (res−1)/2 on each axis, radius R = (res−1)/2,
/// density (1 − (r/R)²)² for r < R (C¹ at the rim), active exactly where the density is > 0.
/// @param res side of the bounding cube in voxels (validated by GenerateOptions)
openvdb::FloatGrid::Ptr makeSphere(int res);

/// @brief Thresholded fractal value noise inside a soft ball, with about @p active active voxels
/// (within kCloudCountTolerance for active ≥ 1000). Deterministic by @p seed for any thread count;
/// memory proportional to the active voxels (the domain is visited leaf by leaf, never stored).
/// @param active target active count (validated by GenerateOptions)
openvdb::FloatGrid::Ptr makeCloud(uint64_t active, uint64_t seed);

/// @brief One tube of makeTubes: a quadratic Bézier axis a → b with control point m, radius r.
/// One sheet: a disc of radius `extent` around a with unit normal n, half-thickness r.
struct TubePrimitive {
    bool sheet = false;
    openvdb::Vec3d a, m, b;  ///< tube: Bézier points; sheet: a is the centre
    openvdb::Vec3d n;        ///< sheet: unit normal
    double extent = 0.0;     ///< sheet: disc radius (voxels)
    double r = 0.0;          ///< tube radius / sheet half-thickness (voxels)
};

/// @brief The tubes and sheets makeTubes draws for these options (deterministic by seed).
std::vector<TubePrimitive> tubeLayout(int res, int count, int sheets, double radiusMin, double radiusMax, uint64_t seed);

/// @brief Distance (voxels) from @p x to the axis of a tube (the polyline of its Bézier, 32
/// segments) or to the mid-surface of a sheet (the disc).
double tubeDistance(const TubePrimitive& t, const openvdb::Vec3d& x);

/// @brief Density at distance @p d from a primitive of radius @p r: 1 for d ≤ r, then
/// (1 − ((d − r)/w)²)² for d < r + w (w = kTubeFalloffVoxels), else 0.
double tubeProfile(double d, double r);

/// @brief Random thin tubes (quadratic Bézier axes crossing the res³ box) and thin discs:
/// density max over primitives of tubeProfile(tubeDistance), active where > 0.
/// Deterministic by @p seed for any thread count. Options validated by GenerateOptions.
openvdb::FloatGrid::Ptr makeTubes(int res, int count, int sheets, double radiusMin, double radiusMax, uint64_t seed);

/// @brief A fireball in the res³ box: "density" (soft union of a main ball and kExplosionLobes
/// random lobes rising upwards, roughened by fractal value noise, values in (0, 1]) and
/// "temperature" (a hotter, noisier core, values in (0, 1], active only where the density is).
/// Deterministic by @p seed for any thread count and compiler.
std::vector<openvdb::FloatGrid::Ptr> makeExplosion(int res, uint64_t seed);

}  // namespace vdbsplat
