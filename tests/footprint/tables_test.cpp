// tests/footprint/tables_test.cpp — the footprint and reindex tables (DESIGN §3): pinned
// closed-form values, lookup error below the bound stated in the header, ∫F = 1,
// deterministic files, and refusal of corrupt, truncated or foreign-kernel files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

#include "footprint/kernel.h"
#include "footprint/reindex.h"
#include "footprint/tables.h"
#include "support/cli.h"
#include "util/error.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::slurp;
using test::spit;
constexpr double kDeg = std::numbers::pi / 180.0;

/// A fresh temporary copy of the shipped tables.
fs::path copyShipped(const std::string& tag) {
    const fs::path dir = fs::temp_directory_path() / ("vdbsplat_tables_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* f : {kFootprintTableFile, kReindexTableFile}) fs::copy_file(defaultTablesDir() / f, dir / f);
    return dir;
}

/// Expects loadTables(dir) to throw an Error whose message names @p file and contains @p what.
void expectRefused(const fs::path& dir, const char* file, const std::string& what) {
    try {
        loadTables(dir);
        ADD_FAILURE() << "loadTables accepted a bad " << file;
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find((dir / file).string()), std::string::npos) << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    }
    EXPECT_THROW(loadOrBuildTables(dir), Error);  // present but bad: refused, not rebuilt
}

TEST(Footprint, PinnedClosedFormValues) {
    // Independent closed form (Python): N e^{−ρ²/2s²} s√(2π) erf(√(R²−ρ²)/(s√2)), s = 0.65, R = 2.
    EXPECT_NEAR(Kernel::footprint(0.0), 0.38502772791377954, 1e-14);
    EXPECT_NEAR(Kernel::footprint(0.5), 0.2861903108075885, 1e-14);
    EXPECT_NEAR(Kernel::footprint(1.0), 0.11724214226486045, 1e-14);  // d = 0.5
    const Tables t = buildTables();
    EXPECT_NEAR(t.footprint.lookupD2(0.0f), 0.38502772791377954, t.footprint.errorBound());
    EXPECT_NEAR(t.footprint.lookupD2(0.25f), 0.11724214226486045, t.footprint.errorBound());
    EXPECT_EQ(t.footprint.lookupD2(1.0f), 0.0f);
    EXPECT_EQ(t.footprint.lookupD2(std::nanf("")), 0.0f);
}

TEST(Footprint, IntegratesToOneOverThePlane) {
    EXPECT_NEAR(Kernel::footprintPlaneIntegral(), 1.0, 1e-6);
    // From the table: ∫∫F dA = π R² ∫_0^1 F dx with x = d² (trapezoid over the samples).
    const Tables t = buildTables();
    const std::vector<float>& v = t.footprint.values();
    double sum = 0.0;
    for (size_t k = 0; k + 1 < v.size(); ++k) sum += 0.5 * (v[k] + v[k + 1]);
    const double integral = std::numbers::pi * Kernel::kRadius * Kernel::kRadius * sum / t.footprint.intervals();
    EXPECT_NEAR(integral, 1.0, 1e-4);
}

TEST(Tables, LookupErrorBelowHeaderBound) {
    const Tables t = loadTables(defaultTablesDir());
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    double worstF = 0.0, worstR = 0.0;
    for (int n = 0; n < 400000; ++n) {
        const float d2 = unit(rng);
        worstF = std::max(worstF, std::abs(t.footprint.lookupD2(d2) - Kernel::footprint(std::sqrt(double(d2)) * Kernel::kRadius)));
        const float i2 = unit(rng);
        const double alpha = unit(rng) * ReindexTable::kAlphaMaxDeg * kDeg;
        worstR = std::max(worstR, std::abs(t.reindex.d2(i2, alpha) - reindex2(i2, alpha)));
    }
    std::printf("footprint table: max error %.3e (random), header max %.3e, bound %.3e; F(0) = %.4f\n", worstF,
                t.footprint.maxAbsError(), t.footprint.errorBound(), Kernel::footprint(0.0));
    std::printf("reindex table:   max error %.3e (random), header max %.3e, bound %.3e\n", worstR,
                t.reindex.maxAbsError(), t.reindex.errorBound());
    RecordProperty("footprint_table_max_error", testing::PrintToString(worstF));
    RecordProperty("reindex_table_max_error", testing::PrintToString(worstR));
    EXPECT_LE(worstF, t.footprint.errorBound());
    EXPECT_LE(worstR, t.reindex.errorBound());
    EXPECT_LE(t.footprint.errorBound(), 1e-4 * Kernel::footprint(0.0) * 2);
    EXPECT_LE(t.reindex.errorBound(), 1e-5);
}

TEST(Tables, ReindexOutsideTheRangeUsesTheFormula) {
    const Tables t = buildTables();
    for (double alphaDeg : {15.5, 20.0, 45.0, 60.0})
        for (float i2 : {0.0f, 0.1f, 0.5f, 0.9f, 0.999f}) {
            const double a = alphaDeg * kDeg;
            EXPECT_NEAR(t.reindex.d2(i2, a), reindex2(i2, a), 1e-6) << alphaDeg << " " << i2;
        }
    EXPECT_NEAR(t.reindex.d2(0.3f, 15.0 * kDeg), reindex2(0.3f, 15.0 * kDeg), t.reindex.errorBound());
    EXPECT_EQ(t.reindex.d2(1.0f, 5.0 * kDeg), 1.0f);
    EXPECT_EQ(t.reindex.d2(0.25f, std::nan("")), 0.25f);  // NaN α: d = i, never NaN
}

TEST(Tables, BuildIsDeterministicAndShippedFilesMatch) {
    const Tables a = buildTables(), b = buildTables();
    EXPECT_EQ(serializeFootprintTable(a.footprint), serializeFootprintTable(b.footprint));
    EXPECT_EQ(serializeReindexTable(a.reindex), serializeReindexTable(b.reindex));
    EXPECT_EQ(slurp(defaultTablesDir() / kFootprintTableFile), serializeFootprintTable(a.footprint));
    EXPECT_EQ(slurp(defaultTablesDir() / kReindexTableFile), serializeReindexTable(a.reindex));
    EXPECT_NO_THROW(checkTables(defaultTablesDir()));
    EXPECT_LT(fs::file_size(defaultTablesDir() / kFootprintTableFile), 1u << 20);
    EXPECT_LT(fs::file_size(defaultTablesDir() / kReindexTableFile), 1u << 20);
}

TEST(Tables, RoundTripThroughFiles) {
    const fs::path dir = fs::temp_directory_path() / ("vdbsplat_tables_rt_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const Tables a = buildTables();
    saveTables(a, dir);
    const Tables b = loadTables(dir);
    EXPECT_EQ(a.footprint.values(), b.footprint.values());
    EXPECT_EQ(a.reindex.values(), b.reindex.values());
    EXPECT_NEAR(b.footprint.errorBound(), a.footprint.errorBound(), 1e-12);
    fs::remove_all(dir);
}

TEST(Tables, FlippedPayloadByteFailsTheChecksum) {
    for (const char* file : {kFootprintTableFile, kReindexTableFile}) {
        const fs::path dir = copyShipped("flip");
        std::string bytes = slurp(dir / file);
        bytes[bytes.size() - 7] ^= 0x10;
        spit(dir / file, bytes);
        expectRefused(dir, file, "checksum");
        EXPECT_THROW(checkTables(dir), Error);
        fs::remove_all(dir);
    }
}

TEST(Tables, TruncatedFileIsRefused) {
    const fs::path dir = copyShipped("trunc");
    const std::string bytes = slurp(dir / kReindexTableFile);
    spit(dir / kReindexTableFile, bytes.substr(0, bytes.size() - 100));
    expectRefused(dir, kReindexTableFile, "truncated");
    spit(dir / kReindexTableFile, bytes.substr(0, 60));
    expectRefused(dir, kReindexTableFile, "truncated");
    fs::remove_all(dir);
}

std::string replaceOnce(std::string s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) s.replace(at, from.size(), to);
    return s;
}

TEST(Tables, TableFromAnotherKernelIsRefused) {
    const std::pair<std::string, std::string> edits[] = {
        {"sigma 0.65\n", "sigma 0.70\n"},
        {"radius 2\n", "radius 3\n"},
        {std::string("kernel ") + Kernel::kName, "kernel gaussian-s0.70-R2.0"}};
    for (const auto& [from, to] : edits) {
        const fs::path dir = copyShipped("kernel");
        spit(dir / kFootprintTableFile, replaceOnce(slurp(dir / kFootprintTableFile), from, to));
        expectRefused(dir, kFootprintTableFile, "kernel");
        fs::remove_all(dir);
    }
}

TEST(Tables, WrongVersionWrongKindAndGarbageAreRefused) {
    const fs::path dir = copyShipped("version");
    const std::string fp = slurp(dir / kFootprintTableFile);
    spit(dir / kFootprintTableFile, replaceOnce(fp, "format_version 1\n", "format_version 2\n"));
    expectRefused(dir, kFootprintTableFile, "version");
    spit(dir / kFootprintTableFile, slurp(defaultTablesDir() / kReindexTableFile));
    expectRefused(dir, kFootprintTableFile, "reindex");
    spit(dir / kFootprintTableFile, "hello\n");
    expectRefused(dir, kFootprintTableFile, "magic");
    fs::remove_all(dir);
}

TEST(Tables, AbsentFilesAreBuiltInMemoryMissingDirRefusedByLoad) {
    const fs::path dir = fs::temp_directory_path() / ("vdbsplat_tables_none_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const Tables t = loadOrBuildTables(dir);
    EXPECT_EQ(t.footprint.values(), buildTables().footprint.values());
    try {
        loadTables(dir);
        ADD_FAILURE() << "loadTables accepted a missing directory";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(kFootprintTableFile), std::string::npos) << e.what();
    }
}

// A FIFO hung the read; a link to /dev/zero read until memory ran out (issue 12).
TEST(Tables, NonRegularAndHugeFilesAreRefusedWithoutReading) {
    const fs::path dir = copyShipped("special");
    fs::remove(dir / kFootprintTableFile);
    ASSERT_EQ(::mkfifo((dir / kFootprintTableFile).c_str(), 0644), 0);
    expectRefused(dir, kFootprintTableFile, "not a regular file");
    fs::remove(dir / kFootprintTableFile);
    fs::create_symlink("/dev/zero", dir / kFootprintTableFile);
    expectRefused(dir, kFootprintTableFile, "not a regular file");
    fs::remove(dir / kFootprintTableFile);
    {
        std::ofstream big(dir / kFootprintTableFile, std::ios::binary);
        big.seekp((std::streamoff(17) << 20) - 1);  // sparse: 17 MiB
        big.put('\0');
    }
    expectRefused(dir, kFootprintTableFile, "MiB");
    fs::remove_all(dir);
}

TEST(Tables, Fnv1a64KnownVectors) {
    EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
    EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
    EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
}

}  // namespace
}  // namespace vdbsplat
