// scripts/bench-load.cpp — times loading a .vdb: one plain OpenVDB read of the grid
// (io::File open without delayed loading + readGrid + close, nothing else) against
// vdbsplat::loadVolume. Built and run by scripts/bench-load.sh; not part of the library.
// Usage: bench-load FILE.vdb plain|load [GRID]   one timed call in this (fresh) process, as
//                                                 `vdbsplat render` loads: prints seconds
//        bench-load FILE.vdb loop RUNS [GRID]     both, interleaved RUNS times in one process
//                                                 (a long-lived caller whose heap holds freed grids)
#include <openvdb/io/File.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "volume/grid.h"

namespace {

double seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 2 ? argv[2] : "";
    if (argc < 3 || (mode != "plain" && mode != "load" && mode != "loop") || (mode == "loop" && argc < 4)) {
        std::fprintf(stderr, "usage: bench-load FILE.vdb plain|load [GRID] | bench-load FILE.vdb loop RUNS [GRID]\n");
        return 2;
    }
    const std::string path = argv[1];
    const int runs = mode == "loop" ? std::max(1, std::atoi(argv[3])) : 1;
    const int gridArg = mode == "loop" ? 4 : 3;
    std::string name = argc > gridArg ? argv[gridArg] : "";
    vdbsplat::initOpenVdb();
    if (name.empty()) {  // the grid loadVolume picks: the first float or double grid (not timed)
        openvdb::io::File file(path);
        file.open(false);
        const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
        for (const auto& meta : *metas)
            if (meta->valueType() == "float" || meta->valueType() == "double") {
                name = meta->getName();
                break;
            }
    }
    const auto plain = [&] {
        const double t0 = seconds();
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false);
        openvdb::GridBase::Ptr grid = file.readGrid(name);
        file.close();
        const double t = seconds() - t0;
        grid.reset();  // freeing is not timed, for either
        return t;
    };
    const auto load = [&] {
        const double t0 = seconds();
        vdbsplat::Volume v = vdbsplat::loadVolume(path, name);
        const double t = seconds() - t0;
        return t;
    };
    if (mode == "plain") {
        std::printf("%.6f\n", plain());
        return 0;
    }
    if (mode == "load") {
        std::printf("%.6f\n", load());
        return 0;
    }
    uint64_t active = vdbsplat::loadVolume(path, name).activeVoxels;  // warm-up
    plain();
    std::vector<double> tPlain, tLoad, ratio;
    for (int i = 0; i < runs; ++i) {
        double a, b;
        if (i % 2 == 0) {
            a = plain();
            b = load();
        } else {
            b = load();
            a = plain();
        }
        tPlain.push_back(a);
        tLoad.push_back(b);
        ratio.push_back(b / a);
    }
    std::printf("%s grid '%s' %llu active voxels, %d runs in one process: plain read median %.4f s (min %.4f), loadVolume median %.4f s "
                "(min %.4f), ratio of medians %.3f, median ratio %.3f\n",
                path.c_str(), name.c_str(), (unsigned long long)active, runs, median(tPlain),
                *std::min_element(tPlain.begin(), tPlain.end()), median(tLoad),
                *std::min_element(tLoad.begin(), tLoad.end()), median(tLoad) / median(tPlain), median(ratio));
    return 0;
}
