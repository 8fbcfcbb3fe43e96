// tests/render/test_pending_tables.cpp — the tables read on a worker (render/pending_tables.h):
// the same tables as a plain load, the same errors, from get() and from render().
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "render/pending_tables.h"
#include "render/render.h"
#include "scenes.h"
#include "util/error.h"

namespace vdbsplat {
namespace {
namespace fs = std::filesystem;
using namespace test;

/// A copy of the shipped tables with one payload byte of footprint.table flipped.
fs::path corruptTables(const std::string& tag) {
    const fs::path dir = fs::temp_directory_path() / ("vdbsplat_pending_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* f : {kFootprintTableFile, kReindexTableFile}) fs::copy_file(defaultTablesDir() / f, dir / f);
    std::ifstream in(dir / kFootprintTableFile, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    bytes[bytes.size() - 7] ^= 0x10;
    std::ofstream(dir / kFootprintTableFile, std::ios::binary | std::ios::trunc) << bytes;
    return dir;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(PendingTables, AreThePlainLoadsTables) {
    PendingTables pending(defaultTablesDir(), KernelShape::standard());
    EXPECT_EQ(&pending.kernel(), &KernelShape::standard());
    const Tables plain = loadOrBuildTables(defaultTablesDir());
    const Tables& t = pending.get();
    EXPECT_EQ(t.footprint.values(), plain.footprint.values());
    EXPECT_EQ(t.reindex.values(), plain.reindex.values());
    EXPECT_EQ(t.kernel, plain.kernel);
    EXPECT_EQ(&pending.get(), &t);  // loaded once
}

TEST(PendingTables, ReportLoadErrorsOnEveryGetAndNoneWhenNeverAsked) {
    const fs::path dir = corruptTables("get");
    std::string plain;
    try {
        loadOrBuildTables(dir);
    } catch (const Error& e) {
        plain = e.what();
    }
    ASSERT_NE(plain.find(kFootprintTableFile), std::string::npos) << plain;
    PendingTables pending(dir, KernelShape::standard());
    EXPECT_EQ(errorOf([&] { pending.get(); }), plain);
    EXPECT_EQ(errorOf([&] { pending.get(); }), plain);
    { PendingTables unused(dir, KernelShape::standard()); }  // destroyed without get(): no throw, no hang
    fs::remove_all(dir);
}

// Through render(): the error a corrupt table gives reaches the caller as before, for every
// forward mode, and a good directory renders.
TEST(PendingTables, RenderReportsACorruptTable) {
    const fs::path dir = corruptTables("render");
    const Volume box = boxVolume({0, 0, 0}, {15, 15, 15});
    for (const RenderMode mode : {RenderMode::Hybrid, RenderMode::Splat, RenderMode::Point}) {
        RenderSettings s = settingsFor(mode, 1.0, 32);
        s.tablesDir = dir.string();
        const std::string error = errorOf([&] { renderWith(box, constantTf(0.5f), s); });
        EXPECT_NE(error.find(kFootprintTableFile), std::string::npos) << toString(mode) << ": " << error;
        EXPECT_NE(error.find("checksum"), std::string::npos) << error;
        s.tablesDir = defaultTablesDir().string();
        EXPECT_EQ(errorOf([&] { renderWith(box, constantTf(0.5f), s); }), "") << toString(mode);
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace vdbsplat
