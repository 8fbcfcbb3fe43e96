// render/reference.cpp — the supersampled ray integrator (see reference.h, DESIGN §1).
#include "render/reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <stdexcept>

#include "footprint/kernel.h"
#include "footprint/prefilter.h"
#include "util/error.h"

namespace vdbsplat {

namespace {

/// The largest kernel radius (KernelShape radii are ≤ Kernel::kRadius): the ray's reach bounds.
constexpr double kR = Kernel::kRadius;
/// Ring of depth bins; must exceed the span of unfinished bins, 2(W + R) + √3 ≤ 16 voxels = 64 bins.
constexpr int kRingSize = 256;

/// E(u) = erf(u / (s√2)) for u ∈ [−R, R], tabulated: the kernel's line-integral primitive.
class ErfTable {
public:
    ErfTable(double s, double R) : R_(R), step_(2.0 * R / (kN - 1)) {
        for (int k = 0; k < kN; ++k) values_[k] = std::erf((-R + k * step_) / (s * std::numbers::sqrt2));
    }
    double operator()(double u) const {
        const double x = std::clamp((u + R_) / step_, 0.0, double(kN - 1));
        const int k = std::min(int(x), kN - 2);
        const double t = x - k;
        return values_[k] + t * (values_[k + 1] - values_[k]);
    }

private:
    static constexpr int kN = 4097;
    double R_, step_;
    std::array<double, kN> values_;
};

/// The table of @p kernel (one of KernelShape's kernels; immutable after construction).
const ErfTable& erfTable(const KernelShape& kernel) {
    static const ErfTable standard(KernelShape::standard().sigma(), KernelShape::standard().radius());
    static const ErfTable sharp(KernelShape::sharp().sigma(), KernelShape::sharp().radius());
    if (&kernel == &KernelShape::sharp()) return sharp;
    if (&kernel != &KernelShape::standard()) throw std::invalid_argument("reference: kernel without an erf table");
    return standard;
}

/// Deterministic hash of three integers to [0, 1) (splitmix64 finaliser).
double hash01(uint64_t a, uint64_t b, uint64_t c) {
    uint64_t z = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull ^ c * 0x94D049BB133111EBull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * (1.0 / 9007199254740992.0);
}

/// Side of the regions ActiveRegions merges leaves into: a lowest internal node (16 leaves of 8).
constexpr int kRegionSide = 128;

/// @p x rounded down to an integer and clamped to [lo, hi] (no undefined conversion of a huge double).
int64_t floorClamped(double x, int64_t lo, int64_t hi) {
    if (!(x > double(lo))) return lo;  // NaN too
    if (x >= double(hi)) return hi;
    return int64_t(std::floor(x));
}

int64_t ceilClamped(double x, int64_t lo, int64_t hi) {
    if (!(x > double(lo))) return lo;
    if (x >= double(hi)) return hi;
    return int64_t(std::ceil(x));
}

/// The slices k (along axis m) where the ray's lateral coordinate on axis @p a,
/// p_a(k) = o_a + (d_a / d_m)(k − o_m), lies in [lo, hi]; false when none.
bool lateralSlices(double oa, double da, double om, double dm, double lo, double hi, double& k0, double& k1) {
    if (std::abs(da) < 1e-15) {
        if (oa < lo || oa > hi) return false;
        k0 = -std::numeric_limits<double>::infinity();
        k1 = std::numeric_limits<double>::infinity();
        return true;
    }
    const double slope = da / dm;
    k0 = om + (lo - oa) / slope;
    k1 = om + (hi - oa) / slope;
    if (k0 > k1) std::swap(k0, k1);
    return true;
}

}  // namespace

ActiveRegions::ActiveRegions(const openvdb::FloatTree& tree) {
    std::map<openvdb::Coord, openvdb::CoordBBox> regions;  // keyed by the 128³ region's origin
    const auto add = [&](const openvdb::CoordBBox& box) {
        if (box.dim().x() > kRegionSide) {
            boxes_.push_back(box);  // a large active tile is its own region
            return;
        }
        const openvdb::Coord key(box.min().x() & ~(kRegionSide - 1), box.min().y() & ~(kRegionSide - 1),
                                 box.min().z() & ~(kRegionSide - 1));
        auto [it, fresh] = regions.try_emplace(key, box);
        if (!fresh) it->second.expand(box);
    };
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf)
        if (leaf->onVoxelCount() > 0) add(leaf->getNodeBoundingBox());
    auto tile = tree.cbeginValueOn();
    tile.setMaxDepth(tile.getLeafDepth() - 1);
    for (; tile; ++tile)
        if (tile.isTileValue()) add(tile.getBoundingBox());
    for (const auto& [key, box] : regions) boxes_.push_back(box);
}

RayIntegrator::RayIntegrator(const Volume& volume, const ClassificationTable& table, const ActiveRegions* regions,
                             const ShadingField* shading, const EmissionSource* emission, const KernelShape& kernel)
    : volume_(volume), table_(table), kernel_(kernel), kernelR2_(kernel.radius() * kernel.radius()),
      accessor_(*volume.tree),
      shading_(shading ? std::make_unique<ShadingField::Accessor>(shading->tree()) : nullptr),
      emission_(emission),
      emissionAccessor_(emission ? std::make_unique<EmissionSource::Accessor>(emission->accessor()) : nullptr),
      bins_(kRingSize),
      ownRegions_(regions ? nullptr : std::make_unique<ActiveRegions>(*volume.tree)),
      regions_(regions ? regions : ownRegions_.get()) {}

std::vector<RayIntegrator::SliceRange>& RayIntegrator::sliceRanges(const glm::dvec3& o, const glm::dvec3& d, int m,
                                                                  double ea, double eb, int64_t kLo, int64_t kHi) {
    const int a = (m + 1) % 3, b = (m + 2) % 3;
    ranges_.clear();
    for (const openvdb::CoordBBox& box : regions_->boxes()) {
        double a0, a1, b0, b1;
        if (!lateralSlices(o[a], d[a], o[m], d[m], box.min()[a] - ea, box.max()[a] + ea, a0, a1)) continue;
        if (!lateralSlices(o[b], d[b], o[m], d[m], box.min()[b] - eb, box.max()[b] + eb, b0, b1)) continue;
        // One slice of margin each side: rounding must never drop a slice the full walk would visit.
        const int64_t first = std::max({int64_t(box.min()[m]), kLo, floorClamped(std::max(a0, b0), kLo, kHi) - 1});
        const int64_t last = std::min({int64_t(box.max()[m]), kHi, ceilClamped(std::min(a1, b1), kLo, kHi) + 1});
        if (first <= last) ranges_.push_back({first, last});
    }
    std::sort(ranges_.begin(), ranges_.end(), [](const SliceRange& x, const SliceRange& y) { return x.first < y.first; });
    size_t n = 0;
    for (const SliceRange& r : ranges_) {
        if (n > 0 && r.first <= ranges_[n - 1].last + 1) ranges_[n - 1].last = std::max(ranges_[n - 1].last, r.last);
        else ranges_[n++] = r;
    }
    ranges_.resize(n);
    return ranges_;
}

bool RayIntegrator::clip(const glm::dvec3& o, const glm::dvec3& d, double& tEnter, double& tExit) const {
    const openvdb::Coord lo = volume_.indexBox.min(), hi = volume_.indexBox.max();
    tEnter = 0.0;
    tExit = std::numeric_limits<double>::max();
    for (int a = 0; a < 3; ++a) {
        const double boxLo = lo[a] - kR, boxHi = hi[a] + kR;
        if (std::abs(d[a]) < 1e-15) {
            if (o[a] < boxLo || o[a] > boxHi) return false;
            continue;
        }
        double t0 = (boxLo - o[a]) / d[a], t1 = (boxHi - o[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        tEnter = std::max(tEnter, t0);
        tExit = std::min(tExit, t1);
    }
    return tEnter < tExit;
}

/// Visits every active kernel whose support sphere the ray crosses, slice by slice along the
/// major axis m of d, front to back. visit(tc, rho, value) per kernel; sliceDone(tFrontier)
/// after each slice with the ray parameter before which no later kernel deposits; it returns
/// false to stop early. Slices far from every active region are skipped: one sliceDone call
/// with the frontier of the last skipped slice stands for theirs (nothing is deposited in
/// between, and compositing is monotone), so the result is the same as visiting them all.
template <typename Visit>
void RayIntegrator::gather(const glm::dvec3& o, const glm::dvec3& d, double tEnter, double tExit, Visit&& visit) {
    const int m = std::abs(d.x) >= std::abs(d.y) ? (std::abs(d.x) >= std::abs(d.z) ? 0 : 2)
                                                  : (std::abs(d.y) >= std::abs(d.z) ? 1 : 2);
    const int a = (m + 1) % 3, b = (m + 2) % 3;
    const double dm = d[m];
    // Lateral half-extents of the slice's kernel disc: |w_a| ≤ R·sqrt(1 − d_b²)/|d_m|.
    const double ea = kR * std::sqrt(std::max(0.0, 1.0 - d[b] * d[b])) / std::abs(dm);
    const double eb = kR * std::sqrt(std::max(0.0, 1.0 - d[a] * d[a])) / std::abs(dm);
    const double reach = std::sqrt(ea * ea + eb * eb) + kR;  // a slice's kernels start at t ≥ t_k − reach
    const openvdb::Coord lo = volume_.indexBox.min(), hi = volume_.indexBox.max();
    const double m0 = o[m] + dm * tEnter, m1 = o[m] + dm * tExit;
    const int step = dm > 0 ? 1 : -1;
    // int64 throughout: a box touching INT_MAX must not overflow a loop counter.
    const int64_t kLo = std::max(floorClamped(std::min(m0, m1) - kR, lo[m], int64_t(hi[m]) + 1), int64_t(lo[m]));
    const int64_t kHi = std::min(ceilClamped(std::max(m0, m1) + kR, int64_t(lo[m]) - 1, hi[m]), int64_t(hi[m]));
    if (kLo > kHi) return;
    const int64_t kLast = step > 0 ? kHi : kLo;
    const std::vector<SliceRange>& ranges = sliceRanges(o, d, m, ea, eb, kLo, kHi);
    bool started = false;
    int64_t previous = 0;
    openvdb::Coord ijk;
    for (size_t r = 0; r < ranges.size(); ++r) {
        const SliceRange& range = ranges[step > 0 ? r : ranges.size() - 1 - r];
        const int64_t from = step > 0 ? range.first : range.last, to = step > 0 ? range.last : range.first;
        for (int64_t k = from;; k += step) {
            if (started && k != previous + step && !visit.sliceDone((k - o[m]) / dm - reach)) return;
            started = true;
            previous = k;
            const double tk = (k - o[m]) / dm;
            const glm::dvec3 p = o + d * tk;
            const int64_t aLo = ceilClamped(p[a] - ea, lo[a], int64_t(hi[a]) + 1);
            const int64_t aHi = floorClamped(p[a] + ea, int64_t(lo[a]) - 1, hi[a]);
            const int64_t bLo = ceilClamped(p[b] - eb, lo[b], int64_t(hi[b]) + 1);
            const int64_t bHi = floorClamped(p[b] + eb, int64_t(lo[b]) - 1, hi[b]);
            ijk[m] = int(k);
            for (int64_t ia = aLo; ia <= aHi; ++ia) {
                ijk[a] = int(ia);
                for (int64_t ib = bLo; ib <= bHi; ++ib) {
                    ijk[b] = int(ib);
                    const glm::dvec3 w = glm::dvec3(ijk.x(), ijk.y(), ijk.z()) - o;
                    const double tc = glm::dot(w, d);
                    const double rho2 = glm::dot(w, w) - tc * tc;
                    if (rho2 >= kernelR2_) continue;
                    float value;
                    if (!accessor_.probeValue(ijk, value)) continue;
                    visit.kernel(tc, rho2, classify(ijk, value));
                }
            }
            if (k == kLast) return;
            const double tNext = (k + step - o[m]) / dm;
            if (!visit.sliceDone(tNext - reach)) return;
            if (k == to) break;
        }
    }
}

Classified RayIntegrator::classify(const openvdb::Coord& ijk, float value) {
    Classified cls = table_(value);
    if (shading_) cls = applyShading(cls, shading_->getValue(ijk));
    return emission_ ? applyEmission(cls, emission_->at(*emissionAccessor_, ijk)) : cls;
}

namespace {

/// The per-ray state of the bin compositor: a ring of depth bins from tEnter on, composited
/// front to back as the slice front passes them (DESIGN §4: C += T·α·c, T *= 1 − α).
struct BinCompositor {
    std::vector<RayIntegrator::Bin>& bins;
    double tEnter;
    /// World length per index length along the ray, over h (rayStretch): 1 for cubic voxels.
    double stretch = 1.0;
    const KernelShape& shape;
    glm::dvec3 color{0.0};
    double transmittance = 1.0;
    int64_t next = 0;     // first bin not yet composited
    int64_t filled = -1;  // last bin deposited into

    int64_t binOf(double t) const { return int64_t(std::floor((t - tEnter) / kBinLength)); }

    void compositeUpTo(int64_t end) {
        for (; next < end; ++next) {
            RayIntegrator::Bin& bin = bins[next % kRingSize];
            if (bin.tau > 0.0) {
                const double alpha = -std::expm1(-bin.tau);
                color += transmittance * alpha * (bin.emission / bin.tau);
                transmittance *= 1.0 - alpha;
            }
            bin = RayIntegrator::Bin{};
        }
    }

    /// Deposits one kernel's exact line integral, bin by bin: τ_bin = σ_k ∫_bin g dt (erf).
    void kernel(double tc, double rho2, const Classified& cls) {
        if (!(cls.sigma > 0.f)) return;
        const ErfTable& E = erfTable(shape);
        const double R = shape.radius(), s = shape.sigma();
        const double halfChord = std::sqrt(R * R - rho2);
        const double tStart = std::max(tc - halfChord, tEnter), tEnd = tc + halfChord;
        if (tEnd <= tStart) return;
        // ∫ N e^{−(ρ²+u²)/2s²} du = N e^{−ρ²/2s²} · s√(π/2) · ΔE(u)
        const double amplitude = stretch * cls.sigma * shape.normalization() * s * std::sqrt(std::numbers::pi / 2.0) *
                                 std::exp(-rho2 / (2.0 * s * s));
        const glm::dvec3 c(cls.color);
        int64_t j = binOf(tStart);
        const int64_t jEnd = binOf(tEnd);
        double prevE = E(tStart - tc);
        if (j < next) {  // cannot happen by the reach bound; never write into a composited bin
            j = next;
            prevE = E(tEnter + j * kBinLength - tc);
        }
        if (jEnd >= next + kRingSize) compositeUpTo(jEnd - kRingSize + 1);  // ring guard, likewise
        for (; j <= jEnd; ++j) {
            const double curE = E(std::min(tEnter + (j + 1) * kBinLength, tEnd) - tc);
            const double tau = amplitude * (curE - prevE);
            prevE = curE;
            RayIntegrator::Bin& bin = bins[j % kRingSize];
            bin.tau += tau;
            bin.emission += tau * c;
        }
        filled = std::max(filled, jEnd);
    }

    bool sliceDone(double frontier) {
        compositeUpTo(std::min(binOf(frontier), filled + 1));
        return transmittance >= kReferenceEpsilon;
    }
};

}  // namespace

/// The ray parameter t runs in index units along the unit index-space direction; σ_k·h (per
/// voxel length) times ∫g dt is the optical depth when a unit of t is h world units (cubic
/// voxels). For any affine voxel a unit of t is |ω|/|A⁻¹ω| world units along the world
/// direction ω: the kernel's line integral is scaled by that over h (1 for cubes, exactly).
static double rayStretch(const Volume& volume, const glm::dvec3& direction) {
    if (volume.isotropic) return 1.0;
    return glm::length(direction) / (glm::length(glm::dmat3(volume.worldToIndex) * direction) * volume.voxelSize);
}

glm::dvec4 RayIntegrator::integrate(const glm::dvec3& origin, const glm::dvec3& direction) {
    const glm::dvec3 o = glm::dvec3(volume_.worldToIndex * glm::dvec4(origin, 1.0));
    const glm::dvec3 d = glm::normalize(glm::dmat3(volume_.worldToIndex) * direction);
    double tEnter, tExit;
    if (!clip(o, d, tEnter, tExit)) return glm::dvec4(0.0);
    std::fill(bins_.begin(), bins_.end(), Bin{});
    BinCompositor compositor{bins_, tEnter, rayStretch(volume_, direction), kernel_};
    gather(o, d, tEnter, tExit, compositor);
    compositor.compositeUpTo(compositor.filled + 1);
    return glm::dvec4(compositor.color, 1.0 - compositor.transmittance);
}

double RayIntegrator::opticalDepth(const glm::dvec3& origin, const glm::dvec3& direction) {
    const glm::dvec3 o = glm::dvec3(volume_.worldToIndex * glm::dvec4(origin, 1.0));
    const glm::dvec3 d = glm::normalize(glm::dmat3(volume_.worldToIndex) * direction);
    double tEnter, tExit;
    if (!clip(o, d, tEnter, tExit)) return 0.0;
    struct Visitor {
        RayIntegrator* self;
        double tEnter, stretch, sum = 0.0;
        void kernel(double tc, double rho2, const Classified& cls) {
            sum += stretch * cls.sigma * self->kernel_.segmentIntegral(std::sqrt(std::max(rho2, 0.0)), tEnter - tc, self->kernel_.radius());
        }
        bool sliceDone(double) { return true; }
    } visitor{this, tEnter, rayStretch(volume_, direction)};
    gather(o, d, tEnter, tExit, visitor);
    return visitor.sum;
}

Image renderReference(const Volume& volume, const ClassificationTable& table, const Camera& camera, int spp,
                      RenderStats& stats, const ShadingField* shading, const RenderControl& control,
                      const EmissionSource* emission, const KernelShape& kernel) {
    const auto start = std::chrono::steady_clock::now();
    const int n = std::max(1, int(std::ceil(std::sqrt(double(spp)) - 1e-9)));  // strata per axis
    stats.raysPerPixel = n * n;
    const double sigmaP = std::sqrt(kPrefilterVariance);
    const int border = int(std::ceil(kPrefilterCutoffSigmas * sigmaP));
    const int W = camera.width(), H = camera.height();
    const int sw = W + 2 * border;  // sample pixels per row
    const double bytesPerRow = double(sw) * n * n * sizeof(glm::vec4);
    if (bytesPerRow * (2 * border + 1) > double(1ull << 30))
        throw Error("--spp: " + std::to_string(n * n) + " rays per pixel at width " + std::to_string(W) +
                    " needs too much memory for the reference");
    // Output rows per band, so a band's samples stay under ~128 MiB.
    const int bandRows = std::clamp(int((128.0 * (1 << 20)) / bytesPerRow) - 2 * border, 1, H);
    Image image(W, H);
    adviseRowsWritten(image, 0, H, W);
    const ActiveRegions regions(*volume.tree);
    std::vector<glm::vec4> samples;
    const double cutoff2 = kPrefilterCutoffSigmas * kPrefilterCutoffSigmas * kPrefilterVariance;
    const int bands = (H + bandRows - 1) / bandRows;
    const double totalRows = double(H + bands * 2 * border);  // sample rows traced over all bands
    std::atomic<int64_t> rowsDone{0};
    std::atomic<bool> stopped{false};

    for (int y0 = 0; y0 < H; y0 += bandRows) {
        const int y1 = std::min(H, y0 + bandRows);
        const int sy0 = y0 - border, sh = (y1 - y0) + 2 * border;
        samples.assign(size_t(sw) * sh * n * n, glm::vec4(0.f));
        const auto samplePos = [&](int px, int py, int s) {
            const int sx = s % n, sy = s / n;
            return PixelCoord(px + (sx + hash01(px, py, 2 * s)) / n, py + (sy + hash01(px, py, 2 * s + 1)) / n);
        };
        tbb::parallel_for(tbb::blocked_range<int>(0, sh, 1), [&](const tbb::blocked_range<int>& rows) {
            RayIntegrator integrator(volume, table, &regions, shading, emission, kernel);
            for (int r = rows.begin(); r < rows.end(); ++r) {
                if (stopped.load(std::memory_order_relaxed) || (control.stop && control.stop())) {
                    stopped.store(true);
                    return;
                }
                for (int c = 0; c < sw; ++c)
                    for (int s = 0; s < n * n; ++s) {
                        const PixelCoord q = samplePos(c - border, sy0 + r, s);
                        samples[(size_t(r) * sw + c) * n * n + s] =
                            glm::vec4(integrator.integrate(camera.eye(), camera.worldRay(q)));
                    }
                if (control.progress) control.progress(double(rowsDone.fetch_add(1) + 1) / totalRows);
            }
        });
        if (stopped.load()) throw RenderStopped("render stopped");
        // Band-limit by the prefilter h_p and sample at pixel centres (DESIGN §1).
        tbb::parallel_for(tbb::blocked_range<int>(y0, y1, 1), [&](const tbb::blocked_range<int>& rows) {
            for (int y = rows.begin(); y < rows.end(); ++y)
                for (int x = 0; x < W; ++x) {
                    const PixelCoord centre(x + 0.5, y + 0.5);
                    glm::dvec4 sum(0.0);
                    double weights = 0.0;
                    for (int py = y - border; py <= y + border; ++py)
                        for (int px = x - border; px <= x + border; ++px)
                            for (int s = 0; s < n * n; ++s) {
                                const PixelCoord q = samplePos(px, py, s);
                                const double r2 = glm::dot(q - centre, q - centre);
                                if (r2 > cutoff2) continue;
                                const double w = std::exp(-0.5 * r2 / kPrefilterVariance);
                                sum += w * glm::dvec4(samples[(size_t(py - sy0) * sw + (px + border)) * n * n + s]);
                                weights += w;
                            }
                    image.at(x, y) = glm::vec4(sum / weights);
                }
        });
    }
    stats.rays += uint64_t(W + 2 * border) * (H + 2 * border) * n * n;
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return image;
}

}  // namespace vdbsplat
