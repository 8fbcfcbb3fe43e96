// render/settings.h — everything that determines an image, in one struct.
// Owns: RenderSettings (validated once, echoed whole into EXR metadata and
// --stats JSON so every run is reproducible from its own output — the OpenVDB
// options-struct pattern) and RenderStats (what a render measured).
#pragma once
#include <array>
#include <nlohmann/json.hpp>
#include <functional>
#include <string>

#include "camera/camera.h"
#include <optional>

#include "composite/compositing.h"
#include "util/error.h"
#include "shading/shading.h"
#include "volume/emission.h"
#include "volume/stream.h"

namespace vdbsplat {

/// --cutoff's range (the default, kDefaultCutoff, is in composite/compositing.h): a pixel may move by
/// at most kMaxCutoff (settings.cpp's error names both).
inline constexpr double kMinCutoff = 1e-6, kMaxCutoff = 0.05;

/// Reference: the ray integrator (ground truth). Hybrid, Splat, Point: Yuan et al. 2003 with the
/// EWA low-pass on the exact perspective ellipse. The study modes (DESIGN §6, docs/modes.md):
///   Ewa  — Zwicker et al. 2001: every voxel a splat from the local affine approximation of the
///          projection (Jacobian at the voxel centre) plus V_h (footprint/ewa.h);
///   Swan — Swan et al. 1997: minified voxels' footprints stretched uniformly to the pixel
///          filter's size, energy kept (footprint/swan.h); magnified voxels as hybrid splats;
///   None — no low-pass: splats without V_h, points to the nearest pixel (the aliasing baseline).
/// Ewa and Swan fold the low-pass into each primitive (the prefilter order) by definition, None
/// has none: the three ignore --filter-order and --subpixels, and None turns --lod off.
enum class RenderMode { Reference, Hybrid, Splat, Point, Ewa, Swan, None };
/// How a splat's footprint index is found (DESIGN §3, docs/footprint.md):
///   Table — affine ellipse→circle index i, then the (i, α) reindex table (the seed's method);
///   Auto  — Table, except splats whose affine-index error tanθ·tanα exceeds
///           kAutoExactIndexError (large, near, off-axis kernels) use the exact per-pixel
///           ray–centre distance; both then read the pre-integrated footprint table;
///   Exact — every splat by the closed-form per-pixel footprint (to measure the others).
enum class FootprintPath { Table, Auto, Exact };

/// Where the screen low-pass h_p (the prefilter, DESIGN §1) is applied in the forward modes:
///   Prefilter  — EWA (Zwicker et al. 2001): each primitive's optical depth is convolved with
///                h_p, then composited. exp(−h_p∗τ) ≠ h_p∗exp(−τ) (Jensen), so structures
///                one or two pixels wide come out too opaque (DESIGN §8.3).
///   Postfilter — composite on a grid of k sub-pixels per pixel and axis (--subpixels, default
///                1: the pixel grid itself) whose primitives carry only a small low-pass, then
///                convolve the composited image with the rest of h_p and sample at pixel
///                centres: the order the reference uses (render/postfilter.h).
enum class FilterOrder { Prefilter, Postfilter };

/// @throw Error "--filter-order: expected 'prefilter' or 'postfilter', got '<name>'".
FilterOrder parseFilterOrder(const std::string& name);
std::string toString(FilterOrder order);

/// @brief `auto` (nullopt: RenderSettings::effectiveCompositing decides), `kernels` or `slabs`.
/// @throw Error "--compositing: expected 'auto', 'kernels' or 'slabs', got '<name>'".
std::optional<CompositingOrder> parseCompositingOrder(const std::string& name);
std::string toString(CompositingOrder order);

/// @brief `auto` (nullopt: RenderSettings::effectiveLodBlend decides), `on`, `off` or `still`.
/// @throw Error "--lod-blend: expected 'auto', 'on', 'off' or 'still', got '<name>'".
std::optional<LodBlend> parseLodBlend(const std::string& name);
std::string toString(LodBlend blend);

/// Postfilter: sub-pixels per axis. kAutoSubpixels (`--subpixels auto`, the default) lets
/// RenderSettings::effectiveSubpixels decide per view; kMaxSubpixels is the most --subpixels accepts.
/// k = 1 with a small V_s already reaches 45–60 dB on the tubes at the cost of the prefilter
/// order; k = 2 adds 0–6 dB for 2–3.5× the time at close views (docs/performance.md).
inline constexpr int kAutoSubpixels = 0, kDefaultSubpixels = kAutoSubpixels, kMaxSubpixels = 8;

/// @throw Error "--footprint: expected 'auto', 'table' or 'exact', got '<name>'".
FootprintPath parseFootprintPath(const std::string& name);
std::string toString(FootprintPath path);

/// The --mode names, in the order --help and the error text list them.
inline constexpr const char* kRenderModeNames = "hybrid, splat, point, ewa, swan, none, reference";

/// @throw Error "--mode: unknown mode '<name>' (choose hybrid, splat, point, ewa, swan, none, reference)".
RenderMode parseRenderMode(const std::string& name);
std::string toString(RenderMode mode);
/// True for the modes that fix where the low-pass goes (Ewa, Swan: in each primitive; None: nowhere).
bool modeFixesFilterOrder(RenderMode mode);
/// True for the modes without a point path (Splat, Ewa, Swan).
bool drawsOnlySplats(RenderMode mode);

/// Default bound on the active voxels (tiles counted voxel by voxel) a render accepts: a
/// few KB of active tiles can hold billions of voxels, hours of work. --max-voxels raises it.
inline constexpr uint64_t kDefaultMaxActiveVoxels = uint64_t(1) << 30;
/// The streaming limit --max-voxels cannot exceed.
inline constexpr uint64_t kHardMaxActiveVoxels = uint64_t(1) << 32;
/// An --eye farther from the grid than this many bounding-box diagonals is refused (it would
/// see the grid as less than a pixel, and the depth arithmetic would lose precision).
inline constexpr double kMaxEyeDistanceInDiagonals = 1e6;

struct RenderSettings {
    RenderMode mode = RenderMode::Hybrid;
    CameraSpec camera;
    std::string transferFunction = "grey";  ///< preset name or JSON file
    std::string gridName;                   ///< empty: the first float/double grid
    int threads = 0;                        ///< 0: all cores
    int spp = 16;                           ///< reference: rays per pixel (rounded to a square)
    double threshold = 1.0;                 ///< τ: projected voxel spacing (px) below which voxels are points
    /// ε, early termination (--cutoff): the deposit that takes a pixel's transmittance below it
    /// takes all of it (the remainder, docs/compositing.md), the pixel takes nothing more, and
    /// blocks and primitives behind such pixels are skipped. A pixel moves by at most ε times the
    /// colour difference between what finished it and what lay behind (kDefaultCutoff: 1e-3).
    double cutoff = kDefaultCutoff;
    FootprintPath footprint = FootprintPath::Auto;
    /// The reconstruction kernel (--kernel; KernelShape::named): every mode and the reference.
    std::string kernel = "gaussian";
    FilterOrder filterOrder = FilterOrder::Postfilter;
    /// Postfilter: sub-pixel grid per axis, 1..kMaxSubpixels; kAutoSubpixels: effectiveSubpixels().
    int subpixels = kDefaultSubpixels;
    /// The grid used: as set, else 2 where Phong shading meets a view in which every voxel is a
    /// point (@p everyVoxelMinified: render.h everyVoxelMinified), else 1. Why: a pixel then spans
    /// several voxels of a surface seen at an angle, so its depth slabs mix the lit shell of the
    /// surface with the layers behind it, whose colour the rays never see (checker box, far view:
    /// 49.4 dB at k = 1, 57.4 at k = 2; docs/shading.md). Unshaded colour does not change from
    /// layer to layer, and at framed and close views a pixel spans under a voxel: k = 1 there.
    /// A view-dependent k switches once along a zoom; `animate` fixes it for the whole path.
    int effectiveSubpixels(bool everyVoxelMinified) const {
        if (subpixels != kAutoSubpixels) return subpixels;
        return shading.mode == ShadingMode::Phong && everyVoxelMinified ? 2 : 1;
    }
    bool showPrimitives = false;            ///< tint splats red (seed Figure 8a)
    /// Level of detail for minified voxels (DESIGN §8.2): points are aggregated over cells of
    /// 2, 4 or 8 voxels per side whose side projects to at most this many pixels; 0: off.
    /// 1.25 (it was 1): a 2³ cell of 0.6 px voxels (a 1024² far view) is aggregated; within the
    /// cap the spread a cell adds beside the points' filter decides (kLodMaxSpreadRatio,
    /// volume/stream.h; docs/performance.md, sessions 3 and 20).
    double lodPx = 1.25;
    /// `--lod PX,PX2`: PX2, the cap for 4³ and 8³ cells in still images (StreamOptions::
    /// lodCoarseCellPx); 0 (the default): lodPx for every level.
    double lodCoarsePx = 0.0;
    /// The second cap in effect: lodCoarsePx where it is above lodPx and the levels do not blend
    /// their first passage (a blended zoom ignores it), else lodPx.
    double effectiveLodCoarsePx() const {
        return lodPx > 0.0 && lodCoarsePx > lodPx && effectiveLodBlend() != LodBlend::On ? lodCoarsePx : lodPx;
    }
    /// How blocks pass from one level of detail to the next (volume/stream.h LodBlend, kLodPassage):
    /// On, blended as the camera moves (no pop in a zoom); Off, each block switches at once where a
    /// level becomes admissible; Still, the first passage (voxels → 2³) switches, the later blend.
    /// Unset (`--lod-blend auto`, the default): effectiveLodBlend() decides.
    std::optional<LodBlend> lodBlend;
    /// The rule used: as set, else Still. `animate` sets On for its frames when unset, so a zoom
    /// never pops; a still image gains nothing from the first passage's blend (docs/performance.md,
    /// session 8: the same or closer to the reference, and 5.6× faster at the checker box far at 1024²).
    LodBlend effectiveLodBlend() const { return lodBlend.value_or(LodBlend::Still); }
    /// Forward modes: each kernel composited whole at its depth (Kernels, DESIGN §4), or every
    /// kernel's optical depth spread over the radial slabs it spans and each slab composited
    /// once (Slabs; composite/compositing.h, docs/compositing.md). The reference ignores it.
    /// Unset (`--compositing auto`, the default): effectiveCompositing() decides.
    std::optional<CompositingOrder> compositing;
    /// The order used: as set, else Slabs where Phong shading makes the colour change from one
    /// voxel layer to the next (the lit shell of every surface: 2–24 dB closer to the reference
    /// at framed and close views, ~1.45× the time there; docs/compositing.md), else Kernels.
    CompositingOrder effectiveCompositing() const {
        if (compositing) return *compositing;
        return shading.mode == ShadingMode::Phong ? CompositingOrder::Slabs : CompositingOrder::Kernels;
    }
    /// Depth slab thickness in voxels (--slab-thickness, [0.5, 1]); 0: automatic, 1 in the kernel
    /// order and ½ in the slab order (docs/compositing.md: half-voxel slabs gain 2–17 dB there).
    double slabThickness = 0.0;
    double effectiveSlabThickness() const {
        return slabThickness > 0.0 ? slabThickness : effectiveCompositing() == CompositingOrder::Slabs ? 0.5 : 1.0;
    }
    /// Splats through the vector loop (Highway, polynomial footprint); false: the scalar table
    /// path it is tested against (same image to ~1e−6; for measuring).
    bool simd = true;
    std::string tablesDir;                  ///< footprint/reindex tables; empty: defaultTablesDir()
    /// Forward modes: composite only the pixel rectangle the volume's kernels can reach (the rest
    /// of the image stays empty); false: the whole image, the oracle the crop is tested against
    /// (same image up to float rounding of pixel coordinates; a speed knob, not in the JSON echo).
    bool cropToVolume = true;
    /// Forward modes: where every colour is grey (a grey transfer function, shaded or not, no
    /// emission, no --show-primitives), the compositor carries one channel (ColorChannels::Grey:
    /// the same image, bit for bit); false: all three, the oracle it is tested against (a speed knob).
    bool greyChannel = true;
    StreamOptions stream;                   ///< how the grid is streamed: speed and memory, never the image
    uint64_t maxActiveVoxels = kDefaultMaxActiveVoxels;  ///< larger grids are refused before any work
    ShadingSettings shading;                ///< off by default: the unshaded emission–absorption image
    EmissionSettings emission;              ///< --emission GRID and its colour map (docs/emission.md); off by default

    /// @throw Error naming the flag of the first invalid value (--tables: DIR must be a directory).
    void validate() const;
    /// The settings as written beside outputs (image metadata, --stats): a setting at its default
    /// that older builds did not write (cutoff, compositing, slab_thickness) is left out, so such
    /// outputs stay as they were.
    nlohmann::json toJson() const;
    /// toJson() with kIdentityOnlyKeys written even at their defaults: what `animate` and `study`
    /// fingerprint for --resume. A default that changes between builds (--cutoff's 1e-4 → 1e-3,
    /// session 40) then makes an older folder's record differ instead of matching silently.
    nlohmann::json identityJson() const;
    /// The settings identityJson() writes at their defaults and toJson() (and builds before session
    /// 41's fingerprints) leave out there (forward modes).
    static constexpr std::array<const char*, 4> kIdentityOnlyKeys = {"cutoff", "compositing", "slab_thickness",
                                                                     "lod_coarse"};
};

struct ForwardBuffers;  // render/forward_buffers.h

/// @brief How a long render reports progress, learns that it should stop (Ctrl-C), and which
/// memory it may reuse. All are optional and none changes the image.
struct RenderControl {
    /// The fraction of the work done, in [0, 1]; called from rendering threads (thread-safe, cheap).
    std::function<void(double)> progress;
    /// Polled before the work, between depth windows (forward modes) and between rows
    /// (reference); returning true makes render() throw RenderStopped.
    std::function<bool()> stop;
    /// Buffers the forward modes keep from one render to the next (render/forward_buffers.h):
    /// a command rendering many images passes one, so their pages are faulted in once; null:
    /// each render has its own. Not shared by renders running at the same time.
    ForwardBuffers* buffers = nullptr;
};

/// @brief Thrown when RenderControl::stop asked the render to end early; nothing was drawn to keep.
class RenderStopped : public Error {
public:
    using Error::Error;
};

struct RenderStats {
    double seconds = 0.0;
    uint64_t activeVoxels = 0;
    uint64_t points = 0, splats = 0;  ///< primitives drawn (not hidden behind opaque tiles)
    uint64_t exactIndexSplats = 0;    ///< of the splats: drawn with the exact index (--footprint auto)
    uint64_t culled = 0;              ///< active voxels that drew nothing (frustum, occlusion, off screen, σ = 0)
    uint64_t culledFrustum = 0;       ///< of those: in blocks outside the view frustum or behind the eye
    uint64_t culledOccluded = 0;      ///< ... in blocks behind opaque tiles, never classified or projected
    uint64_t culledHidden = 0;        ///< ... projected, then dropped: every pixel they touch was opaque (at projection: pixel by pixel; at binning: by tiles)
    uint64_t lodAggregates = 0;       ///< level-of-detail points drawn for aggregates of voxels
    uint64_t lodVoxels = 0;           ///< active voxels those aggregates stand for
    uint64_t windows = 0;             ///< forward modes: depth windows streamed
    uint64_t largestWindow = 0;       ///< forward modes: most voxels in one window
    uint64_t compositedPixels = 0;    ///< forward modes: pixels (sub-pixels) the compositor held (the crop)
    int compositedChannels = 0;       ///< forward modes: colour channels composited (1: grey, RenderSettings::greyChannel; 3)
    /// Minor page faults of the process during the render: the fresh memory it touched, a page (or
    /// a huge page) each. On virtual machines a fault costs microseconds (docs/performance.md,
    /// session 29); a render through kept buffers (RenderControl::buffers) takes few.
    uint64_t pageFaults = 0;
    uint64_t rays = 0;  ///< reference: rays traced
    int raysPerPixel = 0;  ///< reference: the --spp actually used (rounded up to a square)
    double shadingSeconds = 0.0;  ///< the shading pass (0 when shading is off)
    double streamSeconds = 0.0, projectSeconds = 0.0, rasterizeSeconds = 0.0, compositeSeconds = 0.0;
    nlohmann::json toJson() const;
};

}  // namespace vdbsplat
