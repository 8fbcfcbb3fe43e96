// cli/cmd_convert.cpp — `vdbsplat convert IN -o OUT.vdb`: IN is raw (.raw[.gz], needs --dims and
// --type), NRRD (.nrrd, .nhdr) or VTK ImageData (.vti), picked by the file's extension.
// Owns: the flags of the convert command, picking the reader, and refusing flags that a
// header already answers; the readers are volume/raw.h, volume/nrrd.h and volume/vti.h.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <iostream>

#include <CLI/App.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"
#include "volume/grid.h"
#include "volume/nrrd.h"
#include "volume/raw.h"
#include "volume/vti.h"

namespace vdbsplat::cli {

namespace {

enum class Format { Raw, Nrrd, Vti };

Format formatOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".nrrd" || ext == ".nhdr") return Format::Nrrd;
    if (ext == ".vti") return Format::Vti;
    return Format::Raw;
}

ConvertOptions optionsFrom(const Args& args) {
    ConvertOptions o;
    if (auto t = args.get("--threshold")) o.threshold = parseDouble(*t, "--threshold");
    if (auto m = args.get("--max-voxels"))
        o.maxVoxels = uint64_t(parseInt(*m, "--max-voxels", 1, (long long)kHardMaxRawVoxels));
    if (auto a = args.get("--array")) o.array = *a;
    return o;
}

RawSpec specFrom(const Args& args, const ConvertOptions& options) {
    if (args.has("--array")) throw Error("--array: only for .vti input");
    RawSpec spec;
    spec.dims = parseDims(args.require("--dims"), "--dims");
    spec.type = parseRawType(args.require("--type"), "--type");
    if (auto s = args.get("--spacing")) spec.spacing = parseSpacing(*s, "--spacing");
    spec.threshold = options.threshold;
    spec.maxVoxels = options.maxVoxels;
    return spec;
}

/// Refuses the raw-only flags for a file whose header gives them.
void refuseRawFlags(const Args& args, const std::string& in, Format format) {
    const char* field[] = {"sizes / WholeExtent", "type", "spacings / Spacing"};
    const char* flags[] = {"--dims", "--type", "--spacing"};
    for (int i = 0; i < 3; ++i)
        if (args.has(flags[i]))
            throw Error(std::string(flags[i]) + ": conflicts with the header of " + in + " (its " + field[i] +
                        " field gives it; the flag is for raw input only)");
    if (format == Format::Nrrd && args.has("--array")) throw Error("--array: only for .vti input");
}

openvdb::FloatGrid::Ptr convert(const Args& args, const std::string& in, const ConvertOptions& options, RawStats& stats) {
    const Format format = formatOf(in);
    if (format == Format::Raw) return convertRaw(in, specFrom(args, options), &stats);
    refuseRawFlags(args, in, format);
    return format == Format::Nrrd ? convertNrrd(in, options, &stats) : convertVti(in, options, &stats);
}

}  // namespace

void declareConvert(CLI::App& app) {
    app.description(
        "turn a raw, NRRD or VTK ImageData volume into a sparse .vdb\n"
        "\n"
        "usage: vdbsplat convert IN.raw[.gz] -o OUT.vdb --dims X,Y,Z --type T [--spacing SX,SY,SZ]\n"
        "       vdbsplat convert IN.nrrd|IN.nhdr|IN.vti -o OUT.vdb [--array NAME]\n"
        "                        [--threshold T] [--max-voxels N]\n"
        "\n"
        "Converts a volume into a sparse float grid named 'density'. The format is picked by the\n"
        "extension: .nrrd / .nhdr (NRRD, encodings raw and gzip), .vti (VTK XML ImageData: ascii,\n"
        "base64 or appended data, zlib-compressed or not), anything else is headerless raw (x fastest,\n"
        "then y, then z; plain or gzip-compressed). Files are streamed, never read whole (except the\n"
        "XML of a .vti with inline data). NRRD and VTI keep their spacing, origin and directions in\n"
        "the grid's transform; `render` takes any voxel shape and affine transform.");
    addPositional(app, "IN", "the volume to convert: .raw[.gz], .nrrd, .nhdr or .vti");
    addValueFlag(app, "-o", "OUT.vdb", "output file (written atomically)")->required();
    addValueFlag(app, "--dims", "X,Y,Z", "raw only: voxel counts, each 1..65536; the file must hold exactly\n"
                                         "X*Y*Z voxels");
    addValueFlag(app, "--type", "T", "raw only: uint8 | int16 | uint16 | float32 | float64 (little-endian);\n"
                                     "integers are normalised (/255, /32767, /65535), floats are kept");
    addValueFlag(app, "--spacing", "SX,SY,SZ", "raw only: voxel size along x, y, z in world units, each\n"
                                               "1e-4..1e6 (default 1,1,1); anisotropic voxels (e.g. 1,1,2.5)\n"
                                               "render as ellipsoids");
    addValueFlag(app, "--array", "NAME", ".vti only: the PointData array to read (default: the active\n"
                                         "Scalars, else the first one-component array)");
    addValueFlag(app, "--threshold", "T", "a voxel is active iff its normalised value is > T (default 0:\n"
                                          "zeros are background); NaN/inf voxels stay inactive");
    addValueFlag(app, "--max-voxels", "N", "refuse volumes whose X*Y*Z exceeds N (default 2^26 = 67108864,\n"
                                           "at most 2^32)");
}

int runConvert(const Args& args) {
    const std::string in = args.onePositional("input file IN");
    const std::string out = args.require("-o");
    const ConvertOptions options = optionsFrom(args);
    checkRegularOutputPath(out, "-o");
    checkNotAnInput(out, in, "-o");
    const auto start = std::chrono::steady_clock::now();
    RawStats stats;
    auto grid = convert(args, in, options, stats);
    if (stats.active == 0)
        throw Error(in + ": no voxel is above --threshold " + std::to_string(options.threshold) + "; nothing to write");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    writeVolume(out, grid);
    std::cout << "wrote " << out << ": " << stats.active << " active voxels of " << stats.voxels << ", index box "
              << grid->evalActiveVoxelBoundingBox() << ", voxel size " << grid->voxelSize() << ", converted in "
              << seconds << " s";
    if (stats.nonFinite) std::cout << " (" << stats.nonFinite << " NaN/inf voxels left inactive)";
    std::cout << "\n";
    return 0;
}

}  // namespace vdbsplat::cli
