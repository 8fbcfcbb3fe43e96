// cli/cmd_convert.cpp — `vdbsplat convert IN.raw[.gz] -o OUT.vdb --dims X,Y,Z --type T
// [--spacing SX,SY,SZ] [--threshold T]`.
// Owns: the flags of the convert command; the reader itself is volume/raw.h.
#include <chrono>
#include <iostream>

#include "cli/args.h"
#include "cli/commands.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parse.h"
#include "volume/grid.h"
#include "volume/raw.h"

namespace vdbsplat::cli {

namespace {

const char* kHelp =
    "usage: vdbsplat convert IN.raw[.gz] -o OUT.vdb --dims X,Y,Z --type uint8|uint16|float32\n"
    "                        [--spacing SX,SY,SZ] [--threshold T] [--max-voxels N]\n"
    "\n"
    "Converts a headerless raw volume (x fastest, then y, then z; plain or gzip-compressed,\n"
    "streamed, never read whole) into a sparse float grid named 'density'.\n"
    "\n"
    "options:\n"
    "  -o OUT.vdb            output file (written atomically)\n"
    "  --dims X,Y,Z          voxel counts, each 1..65536; the file must hold exactly X*Y*Z voxels\n"
    "  --type T              uint8 | uint16 (little-endian) | float32 (little-endian);\n"
    "                        integers are normalised to [0,1] (/255, /65535), float32 is kept\n"
    "  --spacing SX,SY,SZ    voxel size in world units, 1e-4..1e6 (default 1,1,1); must be uniform\n"
    "                        (non-uniform spacing is refused: the renderer needs cubic voxels)\n"
    "  --threshold T         a voxel is active iff its normalised value is > T (default 0:\n"
    "                        zeros are background); float32 NaN/inf voxels stay inactive\n"
    "  --max-voxels N        refuse --dims whose X*Y*Z exceeds N (default 2^26 = 67108864, at most 2^32)\n";

RawSpec specFrom(const Args& args) {
    RawSpec spec;
    spec.dims = parseDims(args.require("--dims"), "--dims");
    spec.type = parseRawType(args.require("--type"), "--type");
    if (auto s = args.get("--spacing")) spec.spacing = parseUniformSpacing(*s, "--spacing");
    if (auto t = args.get("--threshold")) spec.threshold = parseDouble(*t, "--threshold");
    if (auto m = args.get("--max-voxels"))
        spec.maxVoxels = uint64_t(parseInt(*m, "--max-voxels", 1, (long long)kHardMaxRawVoxels));
    return spec;
}

}  // namespace

int runConvert(const Argv& argv) {
    const Args args(argv, {"-o", "--dims", "--type", "--spacing", "--threshold", "--max-voxels"}, {});
    if (args.wantsHelp()) {
        std::cout << kHelp;
        return 0;
    }
    const std::string in = args.onePositional("input file IN.raw[.gz]");
    const std::string out = args.require("-o");
    const RawSpec spec = specFrom(args);
    checkRegularOutputPath(out, "-o");
    const auto start = std::chrono::steady_clock::now();
    RawStats stats;
    auto grid = convertRaw(in, spec, &stats);
    if (stats.active == 0)
        throw Error(in + ": no voxel is above --threshold " + std::to_string(spec.threshold) + "; nothing to write");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    writeVolume(out, grid);
    std::cout << "wrote " << out << ": " << stats.active << " active voxels of "
              << uint64_t(spec.dims[0]) * spec.dims[1] * spec.dims[2] << ", index box "
              << grid->evalActiveVoxelBoundingBox() << ", voxel size " << spec.spacing << ", converted in " << seconds
              << " s";
    if (stats.nonFinite) std::cout << " (" << stats.nonFinite << " NaN/inf voxels left inactive)";
    std::cout << "\n";
    return 0;
}

}  // namespace vdbsplat::cli
