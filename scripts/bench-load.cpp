// scripts/bench-load.cpp — times loading a .vdb: one plain OpenVDB read of the grid
// (io::File open without delayed loading + readGrid + close, nothing else) against
// vdbsplat::loadVolume, interleaved (ABBA order) so that machine noise hits both alike.
// Built and run by scripts/bench-load.sh; not part of the library or the test suite.
// Usage: bench-load FILE.vdb [RUNS] [GRID]
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
    if (argc < 2) {
        std::fprintf(stderr, "usage: bench-load FILE.vdb [RUNS] [GRID]\n");
        return 2;
    }
    const std::string path = argv[1];
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 7;
    std::string name = argc > 3 ? argv[3] : "";
    vdbsplat::initOpenVdb();
    uint64_t active = 0;
    {
        const vdbsplat::Volume v = vdbsplat::loadVolume(path, name);  // warm-up: page cache, allocator
        name = v.name;
        active = v.activeVoxels;
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
    std::printf("%s grid '%s' %llu active voxels, %d runs: plain read median %.4f s (min %.4f), loadVolume median %.4f s "
                "(min %.4f), ratio of medians %.3f, median ratio %.3f\n",
                path.c_str(), name.c_str(), (unsigned long long)active, runs, median(tPlain),
                *std::min_element(tPlain.begin(), tPlain.end()), median(tLoad),
                *std::min_element(tLoad.begin(), tLoad.end()), median(tLoad) / median(tPlain), median(ratio));
    return 0;
}
