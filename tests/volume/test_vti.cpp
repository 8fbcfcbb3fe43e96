// tests/volume/test_vti.cpp — the VTK ImageData reader (volume/vti.h): files written by VTK's
// vtkXMLImageDataWriter in every mode (ascii, inline base64, appended raw and base64, zlib or
// not, UInt32 and UInt64 headers, several zlib blocks) convert to exactly the raw oracle's
// voxels, Origin/Spacing/Direction kept; hand-made files cover every refusal, each naming the
// file and the field.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>

#include "support/error_of.h"
#include "support/readers.h"
#include "util/error.h"
#include "volume/grid.h"
#include "volume/vti.h"

namespace vdbsplat {
namespace {

namespace fs = std::filesystem;
using test::errorOf;
using test::expectSameVoxels;
using test::fixture;
using test::rawOracle;
using test::worldOf;

openvdb::FloatGrid::Ptr vti(const std::string& path, const std::string& array = "", double threshold = 0.0) {
    ConvertOptions o;
    o.array = array;
    o.threshold = threshold;
    return convertVti(path, o);
}

TEST(VtiFromVtk, EveryModeMatchesRaw) {
    int files = 0;
    for (const std::string kind : {"u8", "u16"}) {
        expectSameVoxels(*rawOracle(kind), *vti(fixture(kind + "_ascii.vti")), kind + "_ascii.vti");
        for (const std::string mode : {"binary", "appended", "appended64"})
            for (const std::string z : {"none", "zlib"})
                for (const std::string h : {"h32", "h64"}) {
                    const std::string name = kind + "_" + mode + "_" + z + "_" + h + ".vti";
                    expectSameVoxels(*rawOracle(kind), *vti(fixture(name)), name);
                    expectSameVoxels(*rawOracle(kind, 0.4), *vti(fixture(name), "", 0.4), name + " threshold 0.4");
                    ++files;
                }
    }
    EXPECT_EQ(files, 24);
    for (const std::string name : {"u16_blocks_zlib_h64.vti", "u16_binary_blocks_zlib_h32.vti"})
        expectSameVoxels(*rawOracle("u16"), *vti(fixture(name)), name);  // several zlib blocks
    expectSameVoxels(*rawOracle("f32"), *vti(fixture("f32_ascii.vti")), "f32_ascii.vti");
    expectSameVoxels(*rawOracle("i16"), *vti(fixture("i16_binary.vti")), "i16_binary.vti");
}

TEST(VtiFromVtk, OriginAndSpacingAreKept) {
    const auto grid = vti(fixture("f32_geometry.vti"));  // Origin -1 2 3.5, Spacing 0.5 0.5 1.25
    expectSameVoxels(*rawOracle("f32"), *grid, "f32_geometry.vti");
    const openvdb::Vec3d o = worldOf(*grid, {0, 0, 0}), p = worldOf(*grid, {1, 1, 1});
    EXPECT_NEAR(o.x(), -1.0, 1e-12);
    EXPECT_NEAR(o.y(), 2.0, 1e-12);
    EXPECT_NEAR(o.z(), 3.5, 1e-12);
    EXPECT_NEAR(p.x(), -0.5, 1e-12);
    EXPECT_NEAR(p.y(), 2.5, 1e-12);
    EXPECT_NEAR(p.z(), 4.75, 1e-12);
}

TEST(VtiFromVtk, DirectionIsARotationTheRendererAccepts) {
    const auto grid = vti(fixture("u8_rotated.vti"));  // 90° about z, Spacing 0.5, Origin 1 2 3
    expectSameVoxels(*rawOracle("u8"), *grid, "u8_rotated.vti");
    const openvdb::Vec3d x = worldOf(*grid, {1, 0, 0}), y = worldOf(*grid, {0, 1, 0});
    EXPECT_NEAR(x.x(), 1.0, 1e-12);  // index x runs along world +y
    EXPECT_NEAR(x.y(), 2.5, 1e-12);
    EXPECT_NEAR(y.x(), 0.5, 1e-12);  // index y runs along world -x
    EXPECT_NEAR(y.y(), 2.0, 1e-12);
    const Volume v = makeVolume(grid);  // cubic voxels: rendering accepts the rotation
    EXPECT_NEAR(v.voxelSize, 0.5, 1e-12);
}

TEST(VtiFromVtk, ArrayChoice) {
    // No active Scalars: the first one-component array ("label", all 3) is read; --array picks.
    const auto first = vti(fixture("u8_two_arrays.vti"));
    EXPECT_EQ(first->activeVoxelCount(), 140u);
    EXPECT_FLOAT_EQ(first->tree().getValue(openvdb::Coord(6, 4, 3)), 3.0f / 255.0f);
    expectSameVoxels(*rawOracle("u8"), *vti(fixture("u8_two_arrays.vti"), "density"), "--array density");
    const std::string msg = errorOf([&] { vti(fixture("u8_two_arrays.vti"), "nope"); });
    EXPECT_NE(msg.find("no DataArray named 'nope' (arrays: label, density)"), std::string::npos) << msg;
}

// --- Hand-made files: what must be refused -----------------------------------------------------

std::string base64(const std::string& bytes) {
    static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const size_t n = std::min<size_t>(3, bytes.size() - i);
        uint32_t v = 0;
        for (size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? uint8_t(bytes[i + k]) : 0);
        for (size_t k = 0; k < 4; ++k) out += k <= n ? abc[(v >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

std::string le32(uint32_t v) { return std::string{char(v), char(v >> 8), char(v >> 16), char(v >> 24)}; }

std::string zlibOf(const std::string& data) {
    std::string out(compressBound(data.size()), '\0');
    uLongf n = out.size();
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &n, reinterpret_cast<const Bytef*>(data.data()), data.size(), 9), Z_OK);
    return out.substr(0, n);
}

class VtiBad : public ::testing::Test {
protected:
    void SetUp() override {
        char tmpl[] = "/tmp/vdbsplat_vti_XXXXXX";
        ASSERT_NE(mkdtemp(tmpl), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }

    /// A 2x2x1 UInt8 image; the parts are replaced by the cases below.
    struct Parts {
        std::string file = R"(type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt32")";
        std::string image = R"(WholeExtent="0 1 0 1 0 0" Origin="0 0 0" Spacing="1 1 1")";
        std::string piece = R"(Extent="0 1 0 1 0 0")";
        std::string array = R"(type="UInt8" Name="d" format="ascii")";
        std::string text = "1 2 3 4";
        std::string appended;  ///< the bytes after '_' (no AppendedData element when empty)
        bool cut = false;      ///< the file ends right after the appended bytes
    };
    std::string write(const std::string& name, const Parts& p) {
        std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile " + p.file + ">\n<ImageData " + p.image + ">\n<Piece " +
                          p.piece + ">\n<PointData>\n<DataArray " + p.array + ">" + p.text +
                          "</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n";
        if (!p.appended.empty()) xml += "<AppendedData encoding=\"raw\">\n _" + p.appended;
        if (!p.cut) xml += (p.appended.empty() ? "" : "\n</AppendedData>\n") + std::string("</VTKFile>\n");
        const std::string path = dir_ + "/" + name;
        std::ofstream(path, std::ios::binary) << xml;
        return path;
    }
    void expectError(const std::string& path, const std::string& needle, const std::string& array = "") {
        const std::string msg = errorOf([&] { vti(path, array); });
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << "wanted '" << needle << "' in: " << msg;
    }
    /// Parts of an appended raw, zlib-compressed 2x2x1 image with the given block header.
    Parts zlibParts(const std::string& header, const std::string& blocks) {
        Parts p;
        p.file += R"( compressor="vtkZLibDataCompressor")";
        p.array = R"(type="UInt8" Name="d" format="appended" offset="0")";
        p.text = "";
        p.appended = header + blocks;
        return p;
    }
    std::string dir_;
};

TEST_F(VtiBad, TheHandMadeControlsConvert) {
    EXPECT_EQ(vti(write("ascii.vti", Parts{}))->activeVoxelCount(), 4u);
    Parts b;
    b.array = R"(type="UInt8" Name="d" format="binary")";
    b.text = base64(le32(4)) + base64("\x01\x02\x03\x04");  // header and data encoded separately, as VTK does
    EXPECT_EQ(vti(write("binary.vti", b))->activeVoxelCount(), 4u);
    const std::string z = zlibOf("\x01\x02\x03\x04");
    const auto grid = vti(write("zlib.vti", zlibParts(le32(1) + le32(4) + le32(4) + le32(uint32_t(z.size())), z)));
    EXPECT_FLOAT_EQ(grid->tree().getValue(openvdb::Coord(1, 1, 0)), 4.0f / 255.0f);
}

TEST_F(VtiBad, MissingOrInconsistentFields) {
    Parts p;
    p.file = R"(type="PolyData" version="1.0")";
    expectError(write("a.vti", p), "VTKFile type: 'PolyData' is not ImageData");
    p = Parts{};
    p.image = R"(Origin="0 0 0")";
    expectError(write("b.vti", p), "ImageData WholeExtent: missing");
    p = Parts{};
    p.piece = R"(Extent="0 1 0 1 0 1")";
    expectError(write("c.vti", p), "Piece Extent: differs from WholeExtent");
    p = Parts{};
    p.image = R"(WholeExtent="0 1 0 1 0")";
    expectError(write("d.vti", p), "WholeExtent: expected 6 numbers");
    p = Parts{};
    p.image = R"(WholeExtent="0 1 0 1 0 0" Spacing="1 1")";
    expectError(write("e.vti", p), "ImageData Spacing: expected 3 numbers");
    expectError(write("f.vti", Parts{}), "no DataArray named 'x' (arrays: d)", "x");
    p = Parts{};
    p.array = R"(type="UInt8" Name="d" format="ascii" NumberOfComponents="3")";
    expectError(write("g.vti", p), "NumberOfComponents: 3", "d");
    expectError(write("g2.vti", p), "PointData: no scalar DataArray");
    std::ofstream(dir_ + "/h.vti") << "<VTKFile type=\"ImageData\"><ImageData";
    expectError(dir_ + "/h.vti", "malformed XML");
    p = Parts{};
    p.array = R"(type="UInt8" Name="d" format="appended")";
    expectError(write("i.vti", p), "format appended, but the file has no AppendedData");
}

TEST_F(VtiBad, UnsupportedTypeEncodingCompressorHeader) {
    Parts p;
    p.array = R"(type="Int32" Name="d" format="ascii")";
    expectError(write("a.vti", p), "unsupported type 'Int32'");
    p = Parts{};
    p.array = R"(type="UInt8" Name="d" format="hex")";
    expectError(write("b.vti", p), "format: unsupported 'hex'");
    p = Parts{};
    p.file += R"( compressor="vtkLZ4DataCompressor")";
    expectError(write("c.vti", p), "VTKFile compressor: unsupported 'vtkLZ4DataCompressor'");
    p = Parts{};
    p.file = R"(type="ImageData" byte_order="LittleEndian" header_type="UInt16")";
    expectError(write("d.vti", p), "VTKFile header_type: 'UInt16'");
    p = Parts{};
    p.file = R"(type="ImageData" byte_order="MiddleEndian")";
    expectError(write("e.vti", p), "byte_order");
}

TEST_F(VtiBad, DataThatDoesNotMatchTheExtent) {
    Parts p;
    p.text = "1 2 3";
    expectError(write("a.vti", p), "holds 3 values, WholeExtent needs 4");
    p.text = "1 2 3 4 5";
    expectError(write("b.vti", p), "more than the 4 values");
    p.text = "1 2 3 256";
    expectError(write("c.vti", p), "'256' is not a uint8 value");
    p.text = "1 2 x 4";
    expectError(write("d.vti", p), "'x' is not a number");
    p = Parts{};
    p.array = R"(type="UInt8" Name="d" format="binary")";
    p.text = base64(le32(5) + "\x01\x02\x03\x04\x05");
    expectError(write("e.vti", p), "holds 5 bytes, WholeExtent needs 4");
    p.text = base64(le32(4) + "\x01\x02\x03");
    expectError(write("f.vti", p), "truncated");
    p.text = base64(le32(4) + "\x01\x02\x03\x04") + base64("extra");
    expectError(write("g.vti", p), "more data than its header gives");
    p.text = "AAAA*AAA";
    expectError(write("h.vti", p), "invalid base64 character");
    p = Parts{};
    p.array = R"(type="UInt8" Name="d" format="appended" offset="0")";
    p.text = "";
    p.appended = le32(4) + "\x01\x02";
    p.cut = true;
    expectError(write("i.vti", p), "truncated");
    p.cut = false;
    p.array = R"(type="UInt8" Name="d" format="appended" offset="999999")";
    expectError(write("j.vti", p), "offset: 999999 is past the end");
}

TEST_F(VtiBad, CompressedBlocksThatLieAboutTheirSize) {
    const std::string four = zlibOf("\x01\x02\x03\x04"), three = zlibOf("\x01\x02\x03"), five = zlibOf("\x01\x02\x03\x04\x05");
    auto header = [](uint32_t blocks, uint32_t size, uint32_t last, const std::vector<uint32_t>& sizes) {
        std::string h = le32(blocks) + le32(size) + le32(last);
        for (uint32_t s : sizes) h += le32(s);
        return h;
    };
    expectError(write("a.vti", zlibParts(header(1, 4, 4, {uint32_t(three.size())}), three)), "inflates to 3 bytes, its header gives 4");
    expectError(write("b.vti", zlibParts(header(1, 4, 4, {uint32_t(five.size())}), five)), "inflates to more than the 4 bytes");
    expectError(write("c.vti", zlibParts(header(1, 4, 4, {uint32_t(four.size()) - 2}), four)), "zlib block 0");
    expectError(write("d.vti", zlibParts(header(1, 4, 4, {1000}), four)), "compressed size 1000 is more than");
    expectError(write("e.vti", zlibParts(header(1, 8, 8, {uint32_t(four.size())}), four)), "gives 8 bytes, WholeExtent needs 4");
    expectError(write("e2.vti", zlibParts(header(2, 8, 2, {3, 3}), four)), "does not fit the 4 bytes");
    expectError(write("f.vti", zlibParts(header(0xffffffffu, 1, 1, {}), four)), "does not fit");
    expectError(write("g.vti", zlibParts(header(2, 2, 2, {3}), four)), "zlib block 0");
    std::string corrupt = four;
    corrupt[3] ^= 0x55;
    expectError(write("h.vti", zlibParts(header(1, 4, 4, {uint32_t(corrupt.size())}), corrupt)), "zlib block 0");
}

TEST_F(VtiBad, AbsurdSizesAndSingularTransforms) {
    Parts p;
    p.image = R"(WholeExtent="0 65535 0 65535 0 65535")";
    p.piece = R"(Extent="0 65535 0 65535 0 65535")";
    expectError(write("a.vti", p), "--max-voxels");
    p.image = R"(WholeExtent="0 99999999 0 1 0 0")";
    expectError(write("b.vti", p), "WholeExtent: axis 0");
    p.image = R"(WholeExtent="0 1 0 1 0 0" Spacing="1 0 1")";
    p.piece = R"(Extent="0 1 0 1 0 0")";
    expectError(write("c.vti", p), "ImageData Spacing/Direction: voxel size 0 along axis 1");
    p.image = R"(WholeExtent="0 1 0 1 0 0" Direction="1 1 0 0 0 0 0 0 1")";
    expectError(write("d.vti", p), "ImageData Spacing/Direction: the axes are singular");
    p.image = R"(WholeExtent="0 1 0 1 0 0" Origin="0 nan 0")";
    expectError(write("e.vti", p), "ImageData Origin");
    p.image = R"(WholeExtent="0 1 0 1 0 0" Origin="0 1e12 0")";
    expectError(write("f.vti", p), "ImageData Origin");
}

TEST_F(VtiBad, AppendedDataWithoutItsMarker) {
    const std::string path = dir_ + "/m.vti";
    std::ofstream(path, std::ios::binary)
        << R"(<VTKFile type="ImageData" byte_order="LittleEndian"><ImageData WholeExtent="0 1 0 1 0 0">)"
        << R"(<Piece Extent="0 1 0 1 0 0"><PointData><DataArray type="UInt8" Name="d" format="appended" offset="0"/>)"
        << R"(</PointData></Piece></ImageData><AppendedData encoding="raw">)" << le32(4) << "abcd</AppendedData></VTKFile>";
    expectError(path, "AppendedData: the '_' marker");
}

}  // namespace
}  // namespace vdbsplat
