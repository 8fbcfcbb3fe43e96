// tests/volumes/test_volumes.cpp — the volume catalogue (volumes/README.md) against the
// scripts that make its files: volumes/fetch.sh --from ../shared/volumes converts every
// classic volume, and each .vdb has the active voxel count and each checked file the sha256
// that the catalogue lists; volumes/make-generated.sh writes the generated volumes with the
// catalogue's counts. A copy with one flipped byte, a damaged .gz, a missing file, a wrong
// file or a bad argument is refused with one "fetch: error:" line, a non-zero exit and no
// .vdb written. Tests that need ../shared/volumes skip when it is absent.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.h"

namespace {

namespace fs = std::filesystem;
using vdbsplat::test::CliResult;
using vdbsplat::test::ScratchDir;
using vdbsplat::test::slurp;
using vdbsplat::test::spit;

const std::string kSource = VDBSPLAT_SOURCE_DIR;
const std::string kShared = std::string(VDBSPLAT_SHARED_DIR) + "/volumes";
const char* kEngine = "engine_256x256x128_uint8.raw";
const char* kBonsai = "bonsai_256x256x256_uint8.raw";

std::string quote(const std::string& s) { return "'" + s + "'"; }

/// @brief Runs `bash volumes/SCRIPT ARGS` (ARGS quoted by the caller) with the test's binary
/// as $VDBSPLAT; stdout and stderr go through files in @p logDir.
CliResult runScript(const std::string& script, const std::string& args, const fs::path& logDir) {
    return vdbsplat::test::runShell("VDBSPLAT=" + quote(VDBSPLAT_BINARY) + " bash " + quote(kSource + "/volumes/" + script) + " " + args,
                          logDir);
}

/// @brief The script's error contract: exit 1, exactly one stderr line "fetch: error: …"
/// containing every one of @p needles.
void expectOneErrorLine(const CliResult& r, const std::vector<std::string>& needles, const std::string& context) {
    EXPECT_EQ(r.rc, 1) << context << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("fetch: error: ", 0), 0u) << context << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << context << "\n" << r.err;
    for (const auto& n : needles)
        EXPECT_NE(r.err.find(n), std::string::npos) << context << "\nexpected '" << n << "' in: " << r.err;
}

/// @brief Every .vdb, and every leftover temporary (a name starting with '.'), under @p dir.
std::vector<std::string> outputsAndTemporaries(const fs::path& dir) {
    std::vector<std::string> found;
    if (!fs::exists(dir)) return found;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() == ".vdb" || name.front() == '.') found.push_back(e.path().string());
    }
    return found;
}

std::string trim(std::string s) {
    const auto keep = [](unsigned char c) { return !std::isspace(c) && c != '`'; };
    s.erase(s.begin(), std::find_if(s.begin(), s.end(), keep));
    s.erase(std::find_if(s.rbegin(), s.rend(), keep).base(), s.end());
    return s;
}

std::vector<std::string> cells(const std::string& row) {
    std::vector<std::string> out;
    std::stringstream s(row.substr(1));
    for (std::string c; std::getline(s, c, '|');) out.push_back(trim(c));
    if (!out.empty() && out.back().empty()) out.pop_back();
    return out;
}

/// @brief One column of the catalogue's tables: for every table in volumes/README.md whose
/// header has a column starting with @p header, first cell (the volume's name) → that cell.
std::map<std::string, std::string> catalogueColumn(const std::string& header) {
    std::map<std::string, std::string> column;
    std::stringstream text(slurp(kSource + "/volumes/README.md"));
    int col = -1;
    for (std::string line; std::getline(text, line);) {
        if (line.empty() || line[0] != '|') {
            col = -1;
            continue;
        }
        const auto c = cells(line);
        if (col < 0) {  // a table's header row
            col = -2;
            for (size_t i = 0; i < c.size(); ++i)
                if (c[i].rfind(header, 0) == 0) col = int(i);
            continue;
        }
        if (col >= 0 && size_t(col) < c.size() && c[0].find("---") == std::string::npos) column[c[0]] = c[col];
    }
    return column;
}

/// @brief The catalogue's active voxel counts by volume name (digits of the cell; "," and
/// spaces are separators).
std::map<std::string, long long> catalogueActive() {
    std::map<std::string, long long> active;
    for (const auto& [name, cell] : catalogueColumn("active voxels")) {
        std::string digits;
        for (char ch : cell)
            if (std::isdigit(static_cast<unsigned char>(ch))) digits += ch;
        if (!digits.empty()) active[name] = std::stoll(digits);
    }
    return active;
}

/// @brief Active voxels of the first grid of @p vdb, from `vdbsplat info`; -1 on failure.
long long activeVoxels(const std::string& vdb, const fs::path& logDir) {
    const CliResult r = vdbsplat::test::runVdbsplat("info " + quote(vdb), logDir);
    const std::string key = "active voxels: ";
    const size_t at = r.out.find(key);
    if (r.rc != 0 || at == std::string::npos) return -1;
    return std::stoll(r.out.substr(at + key.size()));
}

bool sharedPresent() { return fs::is_directory(kShared); }

/// @brief The uncompressed bytes of a shared volume (the tests using it skip without it).
std::string sharedRaw(const std::string& name, const fs::path& logDir) {
    const fs::path out = logDir / name;
    const std::string cmd = "gzip -dc " + quote(kShared + "/" + name + ".gz") + " > " + quote(out.string());
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::string bytes = slurp(out);
    fs::remove(out);
    return bytes;
}

TEST(VolumesCatalogue, ListsEveryVolumeWithItsActiveVoxels) {
    const auto active = catalogueActive();
    // Counts the tests below, the README and docs/fidelity.md rely on.
    EXPECT_EQ(active.count("engine") ? active.at("engine") : -1, 1328027);
    EXPECT_EQ(active.count("checkerbox") ? active.at("checkerbox") : -1, 1000000);
    EXPECT_EQ(active.count("marschner-lobb") ? active.at("marschner-lobb") : -1, 41 * 41 * 41);
    for (const char* name : {"bonsai", "smoke", "sphere", "cloud", "tubes"}) EXPECT_TRUE(active.count(name)) << name;
    const auto sha = catalogueColumn("sha256");
    for (const char* name : {"engine", "bonsai", "smoke"}) {
        ASSERT_TRUE(sha.count(name)) << name;
        EXPECT_EQ(sha.at(name).size(), 64u) << name << ": " << sha.at(name);
    }
}

TEST(VolumesFetch, FromSharedConvertsEveryVolumeAsCatalogued) {
    if (!sharedPresent()) GTEST_SKIP() << kShared << " is absent: nothing to fetch from";
    ScratchDir scratch("fetch-all");
    const std::string out = scratch.path("volumes");
    const CliResult r = runScript("fetch.sh", "--from " + quote(kShared) + " --out " + quote(out) + " all", scratch.dir());
    ASSERT_EQ(r.rc, 0) << r.out << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;

    const auto active = catalogueActive();
    const auto sha = catalogueColumn("sha256");
    const std::map<std::string, std::string> files = {{"engine", kEngine}, {"bonsai", kBonsai}, {"smoke", "smoke.vdb"}};
    for (const auto& [name, file] : files) {
        const std::string vdb = out + "/" + name + ".vdb";
        ASSERT_TRUE(fs::exists(vdb)) << vdb;
        ASSERT_TRUE(active.count(name)) << name << " is not in the catalogue";
        EXPECT_EQ(activeVoxels(vdb, scratch.dir()), active.at(name)) << vdb;
        // The kept, checked copy is the catalogue's file, byte for byte.
        const std::string kept = out + "/downloads/" + file;
        ASSERT_TRUE(fs::exists(kept)) << kept;
        const std::string cmd = "sha256sum " + quote(kept) + " > " + quote(scratch.path("sum.txt"));
        ASSERT_EQ(std::system(cmd.c_str()), 0);
        EXPECT_EQ(slurp(scratch.path("sum.txt")).substr(0, 64), sha.count(name) ? sha.at(name) : "") << kept;
    }
    for (const auto& p : outputsAndTemporaries(out))
        EXPECT_NE(fs::path(p).filename().string().front(), '.') << "temporary left: " << p;

    // A second run over the same folder replaces the outputs and succeeds again.
    const CliResult again = runScript("fetch.sh", "--from " + quote(kShared) + " --out " + quote(out) + " engine",
                                      scratch.dir());
    EXPECT_EQ(again.rc, 0) << again.err;
    EXPECT_EQ(activeVoxels(out + "/engine.vdb", scratch.dir()), 1328027);
}

TEST(VolumesFetch, OneFlippedByteIsRefusedAndNothingIsConverted) {
    if (!sharedPresent()) GTEST_SKIP() << kShared << " is absent: no genuine copy to damage";
    ScratchDir scratch("fetch-flip");
    const fs::path from = scratch.dir() / "from";
    fs::create_directories(from);
    // A good Engine (gzip'd, as shared) beside a plain Bonsai with one byte flipped.
    fs::copy_file(kShared + "/" + kEngine + ".gz", from / (std::string(kEngine) + ".gz"));
    fs::copy_file(kShared + "/smoke.vdb.gz", from / "smoke.vdb.gz");
    std::string bonsai = sharedRaw(kBonsai, scratch.dir());
    ASSERT_EQ(bonsai.size(), 16777216u);
    bonsai[bonsai.size() / 2 + 12345] ^= 0x01;
    const std::string flipped = (from / kBonsai).string();
    spit(flipped, bonsai);

    const std::string out = scratch.path("out");
    const CliResult r = runScript("fetch.sh", "--from " + quote(from.string()) + " --out " + quote(out) + " all",
                                  scratch.dir());
    expectOneErrorLine(r, {flipped, "sha256 mismatch"}, "flipped Bonsai");
    // Nothing converted, not even the good Engine; no temporaries; the bad copy is not kept.
    EXPECT_TRUE(outputsAndTemporaries(out).empty()) << outputsAndTemporaries(out).front();
    EXPECT_FALSE(fs::exists(out + "/downloads/" + kBonsai));

    // Asking for the Bonsai alone fails the same way.
    const CliResult alone = runScript("fetch.sh", "--from " + quote(from.string()) + " --out " + quote(out) + " bonsai",
                                      scratch.dir());
    expectOneErrorLine(alone, {flipped, "sha256 mismatch"}, "flipped Bonsai alone");
    EXPECT_TRUE(outputsAndTemporaries(out).empty());

    // One flipped byte inside the compressed stream of the Engine's .gz copy.
    std::string gz = slurp(kShared + "/" + kEngine + ".gz");
    gz[gz.size() / 2] ^= 0x01;
    const std::string badGz = (from / (std::string(kEngine) + ".gz")).string();
    spit(badGz, gz);
    const CliResult g = runScript("fetch.sh", "--from " + quote(from.string()) + " --out " + quote(out) + " engine",
                                  scratch.dir());
    expectOneErrorLine(g, {badGz}, "flipped byte in the .gz");
    EXPECT_TRUE(outputsAndTemporaries(out).empty());
}

TEST(VolumesFetch, WrongOrMissingFilesAreRefused) {  // needs no shared data
    ScratchDir scratch("fetch-wrong");
    const fs::path from = scratch.dir() / "from";
    fs::create_directories(from);
    const std::string out = scratch.path("out");
    const auto fetch = [&](const std::string& args) { return runScript("fetch.sh", args, scratch.dir()); };
    const std::string opts = "--from " + quote(from.string()) + " --out " + quote(out);

    // The right size, the wrong bytes.
    const std::string wrong = (from / kEngine).string();
    spit(wrong, std::string(256 * 256 * 128, '\x1e'));
    expectOneErrorLine(fetch(opts + " engine"), {wrong, "sha256 mismatch", "expected 15cf29cd"}, "wrong Engine");
    // Missing from the folder.
    expectOneErrorLine(fetch(opts + " bonsai"), {(from / kBonsai).string(), "no such file"}, "missing Bonsai");
    // Not gzip, though named .gz.
    spit((from / "smoke.vdb.gz").string(), "not gzip\n");
    expectOneErrorLine(fetch(opts + " smoke"), {(from / "smoke.vdb.gz").string(), "gzip"}, "bad .gz");
    EXPECT_TRUE(outputsAndTemporaries(out).empty());

    // Bad arguments.
    expectOneErrorLine(fetch(opts + " teapot"), {"unknown volume 'teapot'"}, "unknown name");
    expectOneErrorLine(fetch("--from " + quote(scratch.path("nowhere")) + " engine"), {"nowhere", "no such folder"},
                       "missing --from folder");
    expectOneErrorLine(fetch("--bogus engine"), {"--bogus"}, "unknown option");
    const CliResult none = fetch("");
    EXPECT_EQ(none.rc, 2);
    EXPECT_NE(none.err.find("usage: volumes/fetch.sh"), std::string::npos) << none.err;
    const CliResult help = fetch("--help");
    EXPECT_EQ(help.rc, 0);
    EXPECT_NE(help.out.find("--from DIR"), std::string::npos) << help.out;
    EXPECT_TRUE(outputsAndTemporaries(out).empty());
}

TEST(VolumesMakeGenerated, WritesTheCataloguedVolumes) {
    ScratchDir scratch("make-generated");
    const std::string out = scratch.path("volumes");
    const CliResult r = runScript("make-generated.sh", "--out " + quote(out), scratch.dir());
    ASSERT_EQ(r.rc, 0) << r.out << r.err;
    const auto active = catalogueActive();
    for (const char* name : {"checkerbox", "marschner-lobb", "sphere", "cloud", "tubes"}) {
        const std::string vdb = out + "/" + name + ".vdb";
        ASSERT_TRUE(fs::exists(vdb)) << vdb;
        ASSERT_TRUE(active.count(name)) << name << " is not in the catalogue";
        EXPECT_EQ(activeVoxels(vdb, scratch.dir()), active.at(name)) << vdb;
    }
    const CliResult bad = runScript("make-generated.sh", "--out " + quote(out) + " explosion", scratch.dir());
    EXPECT_EQ(bad.rc, 1);
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find("unknown volume 'explosion'"), std::string::npos) << bad.err;
}

}  // namespace
