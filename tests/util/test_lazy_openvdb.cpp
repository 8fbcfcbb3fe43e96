// tests/util/test_lazy_openvdb.cpp — util/lazy_openvdb.cpp and its generated trampolines
// (cmake/lazy_openvdb_trampolines.sh), on the real `vdbsplat` binary: it does not list
// libopenvdb as NEEDED, commands that never call into libopenvdb (--version, render of a .vdb)
// run without opening it,
// commands that do call into it work (exceptions thrown inside libopenvdb included), and a
// broken installation ends such a command with one error line. With VDBSPLAT_LAZY_OPENVDB OFF
// the binary links libopenvdb at load time: the tests of the lazy binding itself skip, saying
// so; those of commands that call into libopenvdb run either way.
#include <dlfcn.h>
#include <elf.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "support/cli.h"

namespace {

namespace fs = std::filesystem;
using vdbsplat::test::CliResult;
using vdbsplat::test::ScratchDir;
using vdbsplat::test::slurp;

/// The DT_NEEDED entries of the 64-bit ELF file @p path, from its section headers (the
/// SHT_DYNAMIC section and the string table it links to); a test failure if it is not one.
std::vector<std::string> neededLibraries(const std::string& path) {
    const std::string elf = slurp(path);
    std::vector<std::string> needed;
    Elf64_Ehdr eh;
    if (elf.size() < sizeof eh || elf.compare(0, SELFMAG, ELFMAG) != 0 || elf[EI_CLASS] != ELFCLASS64) {
        ADD_FAILURE() << path << ": not a 64-bit ELF file";
        return needed;
    }
    std::memcpy(&eh, elf.data(), sizeof eh);
    auto section = [&](size_t i) {
        Elf64_Shdr sh{};
        const size_t at = eh.e_shoff + i * eh.e_shentsize;
        if (i < eh.e_shnum && at + sizeof sh <= elf.size()) std::memcpy(&sh, elf.data() + at, sizeof sh);
        return sh;
    };
    for (size_t i = 0; i < eh.e_shnum; ++i) {
        const Elf64_Shdr dyn = section(i);
        if (dyn.sh_type != SHT_DYNAMIC) continue;
        const Elf64_Shdr strtab = section(dyn.sh_link);
        for (size_t at = dyn.sh_offset; at + sizeof(Elf64_Dyn) <= dyn.sh_offset + dyn.sh_size; at += sizeof(Elf64_Dyn)) {
            Elf64_Dyn d;
            std::memcpy(&d, elf.data() + at, sizeof d);
            if (d.d_tag == DT_NULL) break;
            if (d.d_tag == DT_NEEDED && strtab.sh_offset + d.d_un.d_val < elf.size())
                needed.emplace_back(elf.c_str() + strtab.sh_offset + d.d_un.d_val);
        }
    }
    return needed;
}

/// The first line of a test of the lazy binding itself: with the option OFF there is none.
#define REQUIRE_LAZY_BINDING()                                                                   \
    if (!VDBSPLAT_LAZY_OPENVDB)                                                                  \
    GTEST_SKIP() << "VDBSPLAT_LAZY_OPENVDB is OFF: vdbsplat links libopenvdb at load time"

class LazyOpenvdb : public ::testing::Test {
protected:
    CliResult run(const std::string& args, const std::string& prefix = "") const {
        return vdbsplat::test::runVdbsplat(args, scratch_.dir(), 0, prefix);
    }

    /// A small .vdb written by `vdbsplat generate` (a command that calls into libopenvdb).
    std::string sphere() const {
        const std::string out = scratch_.path("sphere.vdb");
        const CliResult r = run("generate sphere --res 16 -o '" + out + "'");
        EXPECT_EQ(r.rc, 0) << r.err;
        return out;
    }

    /// A folder holding @p bytes as the library's SONAME, for LD_LIBRARY_PATH: the dynamic
    /// loader, and dlopen, find it before the installed libopenvdb.
    std::string brokenLibrary(const std::string& bytes) const {
        const fs::path dir = scratch_.dir() / "broken";
        fs::create_directories(dir);
        vdbsplat::test::spit(dir / VDBSPLAT_OPENVDB_SONAME, bytes);
        return "LD_LIBRARY_PATH='" + dir.string() + "' ";
    }

    ScratchDir scratch_{"lazy-openvdb"};
};

TEST_F(LazyOpenvdb, TheExecutableDoesNotNeedLibopenvdb) {
    REQUIRE_LAZY_BINDING();
    const std::vector<std::string> needed = neededLibraries(VDBSPLAT_BINARY);
    // The reader sees the libraries the binary does need.
    EXPECT_NE(std::find(needed.begin(), needed.end(), "libc.so.6"), needed.end());
    EXPECT_NE(std::find(needed.begin(), needed.end(), "libstdc++.so.6"), needed.end());
    for (const std::string& n : needed) EXPECT_EQ(n.find("libopenvdb"), std::string::npos) << n;
}

TEST_F(LazyOpenvdb, CommandsThatCallIntoLibopenvdbWork) {
    const std::string vdb = sphere();  // writes through io::File, GridBase, MetaMap, Transform
    const CliResult r = run("info '" + vdb + "'");  // reads every grid through io::File
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("VDB file version"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("density"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(LazyOpenvdb, AnExceptionThrownInLibopenvdbReachesItsCaller) {
    // A map type name that no map has: libopenvdb's map registry throws openvdb::KeyError
    // (called through a trampoline), which vdbsplat's reader turns into one error line with
    // OpenVDB's message. Anything else, such as std::terminate, would not be one line.
    const std::string vdb = sphere();
    std::string bytes = slurp(vdb);
    const size_t map = bytes.find("UniformScaleMap");
    ASSERT_NE(map, std::string::npos);
    bytes.replace(map, 15, "UniformScalePap");
    const fs::path bad = scratch_.dir() / "bad-map.vdb";
    vdbsplat::test::spit(bad, bytes);
    const CliResult r = run("info '" + bad.string() + "'");
    EXPECT_EQ(r.rc, 1);
    vdbsplat::test::expectOneLineError(r, "KeyError: Map UniformScalePap is not registered");
}

TEST_F(LazyOpenvdb, VersionRunsWithoutOpeningLibopenvdb) {
    REQUIRE_LAZY_BINDING();
    // An empty file is no library: the dynamic loader refuses it at start-up when the binary
    // needs it, dlopen when it is opened. --version opens it never.
    const std::string broken = brokenLibrary("");
    const CliResult r = run("--version", broken);
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find(VDBSPLAT_VERSION), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(LazyOpenvdb, RenderingAVdbNeverOpensLibopenvdb) {
    REQUIRE_LAZY_BINDING();
    // vdbsplat's own reader parses the grid, its name and its map (volume/vdb_types.h), and the
    // renderer holds the tree: with an unloadable libopenvdb the render still succeeds, and so
    // does its image through either writer. A call into libopenvdb anywhere on the way would end
    // in "cannot load" (ALibraryThatCannotBeOpenedIsOneErrorLine).
    const std::string vdb = sphere();
    const std::string broken = brokenLibrary("");
    for (const std::string out : {"r.png", "r.exr"}) {
        const CliResult r = run("render '" + vdb + "' --size 32x32 --stats '" + scratch_.path("r.json") + "' -o '" +
                                    scratch_.path(out) + "'",
                                broken);
        EXPECT_EQ(r.rc, 0) << out << ": " << r.err;
        EXPECT_TRUE(fs::exists(scratch_.path(out))) << out;
    }
}

TEST_F(LazyOpenvdb, ALibraryThatCannotBeOpenedIsOneErrorLine) {
    REQUIRE_LAZY_BINDING();
    const std::string vdb = sphere();
    const CliResult r = run("info '" + vdb + "'", brokenLibrary(""));
    EXPECT_EQ(r.rc, 1);
    vdbsplat::test::expectOneLineError(r, std::string("cannot load ") + VDBSPLAT_OPENVDB_SONAME + ": ");
}

TEST_F(LazyOpenvdb, AFunctionMissingFromTheLibraryIsOneErrorLine) {
    REQUIRE_LAZY_BINDING();
    // A real shared library (zlib's, the one this test uses) under libopenvdb's name: it
    // opens, but has none of the functions.
    const std::string vdb = sphere();
    Dl_info zlibInfo{};
    ASSERT_NE(dladdr(reinterpret_cast<void*>(&zlibVersion), &zlibInfo), 0);
    const std::string zlib = slurp(zlibInfo.dli_fname);
    ASSERT_GT(zlib.size(), 1000u) << zlibInfo.dli_fname;
    const CliResult r = run("info '" + vdb + "'", brokenLibrary(zlib));
    EXPECT_EQ(r.rc, 1);
    vdbsplat::test::expectOneLineError(r, "undefined symbol: _ZN7openvdb");
}

}  // namespace
