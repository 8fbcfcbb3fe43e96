// tests/animation/test_folder_record.cpp — the animation folder's camera fingerprint is FNV-1a 64
// (against published values), and --resume's comparison accepts the legacy fingerprint of the
// same cameras and nothing else.
#include <gtest/gtest.h>

#include "animation/folder_record.h"
#include "util/fnv1a.h"

using namespace vdbsplat;

TEST(Fnv1a, PublishedValues) {
    EXPECT_EQ(fnv1aHex(""), "cbf29ce484222325");  // the offset basis
    EXPECT_EQ(fnv1aHex("a"), "af63dc4c8601ec8c");
    EXPECT_EQ(fnv1aHex("foobar"), "85944171f73967e8");
    EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
    // Continuing a hash equals hashing the concatenation.
    EXPECT_EQ(fnv1a64("bar", 3, fnv1a64("foo", 3)), fnv1a64("foobar", 6));
}

TEST(FolderRecord, ResumeAcceptsTheLegacyFingerprintOfTheSameCameras) {
    const std::string cameras = "eye 1,2,3 look-at 0,0,0 up 0,0,1 fov 30 size 8x8\n";
    const nlohmann::json record = {{"frames", 1}, {"cameras_fnv1a", animation::cameraFingerprint(cameras)}};
    EXPECT_EQ(record["cameras_fnv1a"], fnv1aHex(cameras));
    EXPECT_TRUE(animation::sameAnimation(record, record, cameras));
    // A folder written before the fix: the same cameras hashed from the mistyped basis.
    nlohmann::json legacy = record;
    legacy["cameras_fnv1a"] = fnv1aHex(cameras, 1469598103934665603ull);
    ASSERT_NE(legacy, record);
    EXPECT_TRUE(animation::sameAnimation(legacy, record, cameras));
    // Other cameras, under either basis, or another setting: refused.
    const std::string other = "eye 1,2,4 look-at 0,0,0 up 0,0,1 fov 30 size 8x8\n";
    nlohmann::json moved = record;
    moved["cameras_fnv1a"] = fnv1aHex(other, 1469598103934665603ull);
    EXPECT_FALSE(animation::sameAnimation(moved, record, cameras));
    moved["cameras_fnv1a"] = fnv1aHex(other);
    EXPECT_FALSE(animation::sameAnimation(moved, record, cameras));
    nlohmann::json longer = legacy;
    longer["frames"] = 2;
    EXPECT_FALSE(animation::sameAnimation(longer, record, cameras));
}
