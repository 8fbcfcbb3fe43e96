// tests/util/test_atomic_file.cpp — util/atomic_file.h: regular files replaced atomically,
// symbolic links written through (the link stays), devices and FIFOs streamed into or
// refused and never replaced (issue 12), errors naming the user's path.
#include <gtest/gtest.h>

#include <filesystem>

#include <sys/stat.h>

#include "support/cli.h"
#include "support/error_of.h"
#include "util/atomic_file.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::errorOf;
using test::slurp;

TEST(AtomicFile, ReplacesARegularFile) {
    test::ScratchDir dir("atomic");
    test::spit(dir.path("a.json"), "old");
    writeTextFileAtomic(dir.path("a.json"), "new");
    EXPECT_EQ(slurp(dir.path("a.json")), "new");
    test::expectNoTemporaries(dir.dir());
}

TEST(AtomicFile, WritesThroughSymbolicLinks) {
    test::ScratchDir dir("atomic");
    fs::create_directories(dir.path("sub"));
    fs::create_symlink("sub/real.json", dir.path("rel.json"));  // relative to the link's folder
    fs::create_symlink(dir.path("rel.json"), dir.path("chain.json"));
    writeTextFileAtomic(dir.path("chain.json"), "x");
    EXPECT_TRUE(fs::is_symlink(dir.path("chain.json")));
    EXPECT_TRUE(fs::is_symlink(dir.path("rel.json")));
    EXPECT_EQ(slurp(dir.path("sub/real.json")), "x");
    EXPECT_EQ(resolveOutputPath(dir.path("chain.json")), dir.path("sub/real.json"));
    fs::create_symlink("loop2", dir.path("loop1"));
    fs::create_symlink("loop1", dir.path("loop2"));
    EXPECT_NE(errorOf([&] { writeTextFileAtomic(dir.path("loop1"), "x"); }).find("symbolic links"), std::string::npos);
    fs::create_symlink("nowhere/x.json", dir.path("dangling.json"));
    EXPECT_NE(errorOf([&] { checkOutputPath(dir.path("dangling.json")); }).find("dangling.json"), std::string::npos);
}

TEST(AtomicFile, StreamsIntoDevicesAndNeverReplacesThem) {
    test::ScratchDir dir("atomic");
    fs::create_symlink("/dev/null", dir.path("null.json"));
    EXPECT_EQ(checkOutputPath(dir.path("null.json")), OutputKind::Special);
    writeTextFileAtomic(dir.path("null.json"), "discarded");
    EXPECT_TRUE(fs::is_symlink(dir.path("null.json")));
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
    // A FIFO without a reader: an error naming it, not a hang; it stays a FIFO.
    ASSERT_EQ(::mkfifo(dir.path("f.json").c_str(), 0644), 0);
    const std::string msg = errorOf([&] { writeTextFileAtomic(dir.path("f.json"), "x"); });
    EXPECT_NE(msg.find("f.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no reader"), std::string::npos) << msg;
    EXPECT_TRUE(fs::is_fifo(dir.path("f.json")));
    EXPECT_NE(errorOf([&] { checkRegularOutputPath(dir.path("f.json"), "-o"); }).find("-o: "), std::string::npos);
    test::expectNoTemporaries(dir.dir());
}

TEST(AtomicFile, DirectoryAndMissingFolderAreRefused) {
    test::ScratchDir dir("atomic");
    EXPECT_NE(errorOf([&] { writeTextFileAtomic(dir.dir().string(), "x"); }).find("is a directory"), std::string::npos);
    EXPECT_NE(errorOf([&] { writeTextFileAtomic(dir.path("no/x.json"), "x"); }).find("does not exist"),
              std::string::npos);
}

}  // namespace
}  // namespace vdbsplat
