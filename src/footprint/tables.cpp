// footprint/tables.cpp — building, measuring, writing and verifying the footprint and
// reindex tables (DESIGN §3; see tables.h for the contracts).
//
// File layout (format_version 1): ASCII header lines "key value", the first line
// "vdbsplat-table", the last "end_header"; then the payload, little-endian float32.
// The checksum (FNV-1a 64) covers the payload; the header fields are each validated.
#include "footprint/tables.h"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <tuple>

#include "footprint/kernel.h"
#include "footprint/reindex.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vdbsplat {

static_assert(std::endian::native == std::endian::little, "table payloads are little-endian float32");

namespace {

constexpr const char* kMagic = "vdbsplat-table";
constexpr const char* kEndHeader = "end_header\n";
constexpr double kDeg = std::numbers::pi / 180.0;

std::string fmt(const char* f, double x) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, x);
    return buf;
}

/// The stated bound: 1.25 × the measured maximum, rounded up to two significant digits.
double statedBound(double measured) {
    const double x = 1.25 * measured;
    if (!(x > 0.0)) return 1e-12;
    const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1.0);
    return std::ceil(x / unit) * unit;
}

std::string payloadBytes(const std::vector<float>& v) {
    std::string s(v.size() * sizeof(float), '\0');
    std::memcpy(s.data(), v.data(), s.size());
    return s;
}

std::string hex64(std::uint64_t h) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

/// Header lines common to both tables (kernel identity, version).
std::string commonHeader(const char* kind, const KernelShape& kernel) {
    std::string h = std::string(kMagic) + "\n";
    h += "format_version " + std::to_string(kTableFormatVersion) + "\n";
    h += std::string("table ") + kind + "\n";
    h += std::string("kernel ") + kernel.tableName() + "\n";
    h += "sigma " + fmt("%.10g", kernel.sigma()) + "\n";
    h += "radius " + fmt("%.10g", kernel.radius()) + "\n";
    return h;
}

std::string finishFile(std::string header, const std::vector<float>& values, double maxErr, double bound) {
    const std::string payload = payloadBytes(values);
    header += "max_abs_error " + fmt("%.3e", maxErr) + "\n";
    header += "error_bound " + fmt("%.2e", bound) + "\n";
    header += "payload float32le " + std::to_string(payload.size()) + "\n";
    header += "checksum fnv1a64 " + hex64(fnv1a64(payload.data(), payload.size())) + "\n";
    return header + kEndHeader + payload;
}

// --- parsing -----------------------------------------------------------------

struct ParsedFile {
    std::string name;
    std::map<std::string, std::string> kv;
    std::string payload;

    [[noreturn]] void fail(const std::string& what) const { throw Error(name + ": " + what); }

    const std::string& get(const std::string& key) const {
        const auto it = kv.find(key);
        if (it == kv.end()) fail("table header lacks '" + key + "' (corrupt or not a vdbsplat table)");
        return it->second;
    }
    double number(const std::string& key) const {
        std::istringstream in(get(key));
        double x;
        if (!(in >> x) || !std::isfinite(x)) fail("table header: bad value for '" + key + "'");
        return x;
    }
    std::vector<double> numbers(const std::string& key, size_t n) const {
        std::istringstream in(get(key));
        std::vector<double> v(n);
        for (double& x : v)
            if (!(in >> x) || !std::isfinite(x)) fail("table header: bad value for '" + key + "'");
        return v;
    }
};

ParsedFile splitFile(const std::string& bytes, const std::string& name) {
    ParsedFile p{name, {}, {}};
    if (bytes.rfind(std::string(kMagic) + "\n", 0) != 0) p.fail("not a vdbsplat table (bad magic)");
    const size_t end = bytes.find(kEndHeader);
    if (end == std::string::npos) p.fail("truncated table (no end_header line)");
    std::istringstream lines(bytes.substr(0, end));
    std::string line;
    std::getline(lines, line);  // magic
    while (std::getline(lines, line)) {
        const size_t sp = line.find(' ');
        if (sp == std::string::npos) p.fail("malformed table header line '" + line + "'");
        p.kv[line.substr(0, sp)] = line.substr(sp + 1);
    }
    p.payload = bytes.substr(end + std::strlen(kEndHeader));
    return p;
}

/// Version, table kind and kernel identity: checked before anything else in the header.
void verifyIdentity(const ParsedFile& p, const std::string& kind, const KernelShape& kernel) {
    if (p.get("format_version") != std::to_string(kTableFormatVersion))
        p.fail("table format version " + p.get("format_version") + ", this build reads version " +
               std::to_string(kTableFormatVersion) + " (regenerate with `vdbsplat tables --out DIR`)");
    if (p.get("table") != kind) p.fail("is a '" + p.get("table") + "' table, expected '" + kind + "'");
    const double sigma = p.number("sigma"), radius = p.number("radius");
    if (p.get("kernel") != kernel.tableName() || std::abs(sigma - kernel.sigma()) > 1e-9 ||
        std::abs(radius - kernel.radius()) > 1e-9)
        p.fail("table built for kernel '" + p.get("kernel") + "' (s_g " + fmt("%g", sigma) + ", R " +
               fmt("%g", radius) + "), this build uses '" + kernel.tableName() + "' (s_g " +
               fmt("%g", kernel.sigma()) + ", R " + fmt("%g", kernel.radius()) + ")");
}

/// Payload size and checksum; returns the float payload.
std::vector<float> verifyPayload(const ParsedFile& p, size_t expectedValues) {
    const std::string expect = "float32le " + std::to_string(expectedValues * sizeof(float));
    if (p.get("payload") != expect) p.fail("table header says payload '" + p.get("payload") + "', expected '" + expect + "'");
    if (p.payload.size() != expectedValues * sizeof(float))
        p.fail("truncated or oversized table: payload has " + std::to_string(p.payload.size()) + " bytes, header says " +
               std::to_string(expectedValues * sizeof(float)));
    const std::string sum = "fnv1a64 " + hex64(fnv1a64(p.payload.data(), p.payload.size()));
    if (p.get("checksum") != sum)
        p.fail("checksum mismatch (header '" + p.get("checksum") + "', payload '" + sum +
               "'): the table is corrupt; regenerate with `vdbsplat tables --out DIR`");
    std::vector<float> v(expectedValues);
    std::memcpy(v.data(), p.payload.data(), p.payload.size());
    for (float x : v)
        if (!std::isfinite(x)) p.fail("table holds a non-finite value");
    return v;
}

int intervalCount(const ParsedFile& p, double x) {
    if (x != std::floor(x) || x < 2 || x > (1 << 20)) p.fail("table header: bad interval count");
    return static_cast<int>(x);
}

/// Largest table file read (the shipped ones are ~16 and ~32 KB): a table directory is
/// user input, and a link to /dev/zero or a huge file must not be read until memory runs out.
constexpr std::uintmax_t kMaxTableFileBytes = std::uintmax_t(16) << 20;

/// The whole file, refusing non-regular files (a FIFO would block, a device never end) and
/// anything larger than kMaxTableFileBytes; reads at most that much even if it grows.
std::string readFile(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error(path.string() + ": not a regular file (table files must be plain files)");
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path.string() + ": cannot read table file: " + ec.message());
    if (size > kMaxTableFileBytes)
        throw Error(path.string() + ": table file is " + std::to_string(size) + " bytes, more than the " +
                    std::to_string(kMaxTableFileBytes >> 20) + " MiB a table may have");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open table file");
    std::string bytes(size_t(size) + 1, '\0');  // one byte more shows a file that grew meanwhile
    in.read(bytes.data(), std::streamsize(bytes.size()));
    if (in.bad()) throw Error(path.string() + ": cannot read table file");
    bytes.resize(size_t(in.gcount()));
    if (bytes.size() > size) throw Error(path.string() + ": table file changed while it was read");
    return bytes;
}

/// Temporary file + rename: an interrupted `tables --out` never leaves a torn table.
void writeFile(const std::filesystem::path& path, const std::string& bytes) {
    writeTextFileAtomic(path.string(), bytes);
}

}  // namespace

// --- FootprintTable ------------------------------------------------------------

FootprintTable::FootprintTable(std::vector<float> values, double maxAbsError, double errorBound)
    : v_(std::move(values)), maxAbsError_(maxAbsError), errorBound_(errorBound) {
    last_ = static_cast<int>(v_.size()) - 2;
    scale_ = static_cast<float>(last_ + 1);
}

FootprintTable FootprintTable::build(int intervals, const KernelShape& kernel) {
    std::vector<float> v(intervals + 1);
    for (int k = 0; k <= intervals; ++k) {
        const double d2 = static_cast<double>(k) / intervals;
        v[k] = static_cast<float>(kernel.footprint(std::sqrt(d2) * kernel.radius()));
    }
    FootprintTable t(std::move(v), 0.0, 0.0);
    t.maxAbsError_ = measureFootprintError(t, kernel);
    t.errorBound_ = statedBound(t.maxAbsError_);
    return t;
}

double measureFootprintError(const FootprintTable& t, const KernelShape& kernel) {
    constexpr int kSub = 16;
    const int n = t.intervals() * kSub;
    double worst = 0.0;
    for (int k = 0; k <= n; ++k) {
        const float d2 = static_cast<float>(static_cast<double>(k) / n);
        const double exact = kernel.footprint(std::sqrt(static_cast<double>(d2)) * kernel.radius());
        worst = std::max(worst, std::abs(t.lookupD2(d2) - exact));
    }
    return worst;
}

// --- ReindexTable --------------------------------------------------------------

ReindexTable::ReindexTable(std::vector<float> values, int intervalsI2, int intervalsAlpha, double alphaMaxDeg,
                           double maxAbsError, double errorBound)
    : v_(std::move(values)), nI2_(intervalsI2), nAlpha_(intervalsAlpha), alphaMaxDeg_(alphaMaxDeg),
      alphaMax_(alphaMaxDeg * kDeg), maxAbsError_(maxAbsError), errorBound_(errorBound) {}

ReindexTable ReindexTable::build(int intervalsI2, int intervalsAlpha, double alphaMaxDeg) {
    const int rowLen = intervalsI2 + 1;
    std::vector<float> v(static_cast<size_t>(rowLen) * (intervalsAlpha + 1));
    for (int j = 0; j <= intervalsAlpha; ++j) {
        const double alpha = alphaMaxDeg * kDeg * j / intervalsAlpha;
        for (int k = 0; k <= intervalsI2; ++k)
            v[static_cast<size_t>(j) * rowLen + k] = static_cast<float>(reindex2(static_cast<double>(k) / intervalsI2, alpha));
    }
    ReindexTable t(std::move(v), intervalsI2, intervalsAlpha, alphaMaxDeg, 0.0, 0.0);
    t.maxAbsError_ = measureReindexError(t);
    t.errorBound_ = statedBound(t.maxAbsError_);
    return t;
}

ReindexTable::Row ReindexTable::row(double alpha) const {
    Row r;
    if (!(alpha >= 0.0)) return r;  // NaN or negative: the formula with α = 0, d² = i²
    if (alpha > alphaMax_ || v_.empty()) {
        const double s = std::sin(alpha), c = std::cos(alpha);
        r.cos2 = static_cast<float>(c * c), r.sin2 = static_cast<float>(s * s);
        return r;
    }
    const double t = alpha / alphaMax_ * nAlpha_;
    const int j = std::min(static_cast<int>(t), nAlpha_ - 1);
    const size_t rowLen = static_cast<size_t>(nI2_) + 1;
    r.r0 = v_.data() + j * rowLen;
    r.r1 = r.r0 + rowLen;
    r.wAlpha = static_cast<float>(t - j);
    r.scale = static_cast<float>(nI2_);
    r.last = nI2_ - 1;
    return r;
}

double measureReindexError(const ReindexTable& t) {
    constexpr int kSub = 8;
    const int nI = t.intervalsI2() * kSub, nA = t.intervalsAlpha() * kSub;
    double worst = 0.0;
    for (int j = 0; j <= nA; ++j) {
        const double alpha = t.alphaMaxDeg() * kDeg * j / nA;
        const ReindexTable::Row row = t.row(alpha);
        for (int k = 0; k <= nI; ++k) {
            const float i2 = static_cast<float>(static_cast<double>(k) / nI);
            worst = std::max(worst, std::abs(row.d2(i2) - reindex2(i2, alpha)));
        }
    }
    return worst;
}

// --- files -----------------------------------------------------------------------

std::string serializeFootprintTable(const FootprintTable& t, const KernelShape& kernel) {
    std::string h = commonHeader("footprint", kernel);
    h += "index d2\n";
    h += "domain 0 1\n";
    h += "intervals " + std::to_string(t.intervals()) + "\n";
    h += "value F(d) = line integral (voxel units) of the normalised kernel at distance d*R from its centre\n";
    return finishFile(h, t.values(), t.maxAbsError(), t.errorBound());
}

std::string serializeReindexTable(const ReindexTable& t) {
    std::string h = commonHeader("reindex", KernelShape::standard());  // geometry only: one file for every kernel
    h += "index i2 alpha_deg (alpha rows, i2 fastest)\n";
    h += "domain_i2 0 1\n";
    h += "domain_alpha_deg 0 " + fmt("%.10g", t.alphaMaxDeg()) + "\n";
    h += "intervals " + std::to_string(t.intervalsI2()) + " " + std::to_string(t.intervalsAlpha()) + "\n";
    h += "value d2 = i2 / (cos^2 alpha + i2 sin^2 alpha)\n";
    return finishFile(h, t.values(), t.maxAbsError(), t.errorBound());
}

FootprintTable parseFootprintTable(const std::string& bytes, const std::string& name, const KernelShape& kernel) {
    const ParsedFile p = splitFile(bytes, name);
    verifyIdentity(p, "footprint", kernel);
    const int n = intervalCount(p, p.number("intervals"));
    if (p.get("index") != "d2" || p.get("domain") != "0 1") p.fail("footprint table: unsupported index or domain");
    std::vector<float> v = verifyPayload(p, static_cast<size_t>(n) + 1);
    return FootprintTable(std::move(v), p.number("max_abs_error"), p.number("error_bound"));
}

ReindexTable parseReindexTable(const std::string& bytes, const std::string& name) {
    const ParsedFile p = splitFile(bytes, name);
    verifyIdentity(p, "reindex", KernelShape::standard());
    const std::vector<double> n = p.numbers("intervals", 2);
    const int nI2 = intervalCount(p, n[0]), nAlpha = intervalCount(p, n[1]);
    if (p.get("domain_i2") != "0 1") p.fail("reindex table: unsupported i2 domain");
    const std::vector<double> dom = p.numbers("domain_alpha_deg", 2);
    if (dom[0] != 0.0 || !(dom[1] > 0.0 && dom[1] <= 60.0)) p.fail("reindex table: unsupported alpha domain");
    std::vector<float> v = verifyPayload(p, static_cast<size_t>(nI2 + 1) * (nAlpha + 1));
    return ReindexTable(std::move(v), nI2, nAlpha, dom[1], p.number("max_abs_error"), p.number("error_bound"));
}

std::string footprintTableFile(const KernelShape& kernel) {
    if (&kernel == &KernelShape::standard()) return kFootprintTableFile;
    return std::string("footprint-") + kernel.id() + ".table";
}

Tables buildTables(const KernelShape& kernel) {
    return {FootprintTable::build(FootprintTable::kIntervals, kernel), ReindexTable::build(),
            FootprintPolynomials::build(kernel), &kernel};
}

std::filesystem::path defaultTablesDir() { return std::filesystem::path(VDBSPLAT_SOURCE_DIR) / "tables"; }

void saveTables(const Tables& tables, const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(dir.string() + ": cannot create directory (" + ec.message() + ")");
    writeFile(dir / footprintTableFile(*tables.kernel), serializeFootprintTable(tables.footprint, *tables.kernel));
    writeFile(dir / kReindexTableFile, serializeReindexTable(tables.reindex));
}

Tables loadTables(const std::filesystem::path& dir, const KernelShape& kernel) {
    const std::filesystem::path fp = dir / footprintTableFile(kernel), ri = dir / kReindexTableFile;
    return {parseFootprintTable(readFile(fp), fp.string(), kernel), parseReindexTable(readFile(ri), ri.string()),
            FootprintPolynomials::build(kernel), &kernel};
}

Tables loadOrBuildTables(const std::filesystem::path& dir, const KernelShape& kernel) {
    const std::filesystem::path fp = dir / footprintTableFile(kernel), ri = dir / kReindexTableFile;
    Tables t;
    t.footprint = std::filesystem::exists(fp) ? parseFootprintTable(readFile(fp), fp.string(), kernel)
                                              : FootprintTable::build(FootprintTable::kIntervals, kernel);
    t.reindex = std::filesystem::exists(ri) ? parseReindexTable(readFile(ri), ri.string()) : ReindexTable::build();
    t.poly = FootprintPolynomials::build(kernel);
    t.kernel = &kernel;
    return t;
}

std::vector<std::string> checkTables(const std::filesystem::path& dir) {
    std::vector<std::string> summary;
    // The reindex table once, then each kernel's footprint table (tables.h: footprintTableFile).
    const KernelShape* kernels[] = {&KernelShape::standard(), &KernelShape::sharp()};
    for (const KernelShape* kernel : kernels) {
        const Tables fresh = buildTables(*kernel);
        std::vector<std::tuple<std::string, std::string, double>> files = {
            {footprintTableFile(*kernel), serializeFootprintTable(fresh.footprint, *kernel), fresh.footprint.maxAbsError()}};
        if (kernel == kernels[0])
            files.insert(files.begin() + 1, {kReindexTableFile, serializeReindexTable(fresh.reindex), fresh.reindex.maxAbsError()});
        const Tables loaded = loadTables(dir, *kernel);  // parse + checksum + kernel identity first
        (void)loaded;
        for (const auto& [file, expected, error] : files) {
            const std::filesystem::path path = dir / file;
            const std::string actual = readFile(path);
            if (actual != expected) {
                size_t at = 0;
                while (at < actual.size() && at < expected.size() && actual[at] == expected[at]) ++at;
                throw Error(path.string() + ": differs from a fresh build at byte " + std::to_string(at) + " (" +
                            std::to_string(actual.size()) + " vs " + std::to_string(expected.size()) +
                            " bytes); regenerate with `vdbsplat tables --out DIR`");
            }
            summary.push_back(path.string() + ": ok (" + std::to_string(actual.size()) +
                              " bytes, matches a fresh build), max error " + fmt("%.3e", error));
        }
    }
    return summary;
}

}  // namespace vdbsplat
