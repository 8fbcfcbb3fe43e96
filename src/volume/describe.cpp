// volume/describe.cpp — `vdbsplat info` text (placeholder; the volume work fills it in).
#include "util/error.h"
#include "volume/grid.h"

namespace vdbsplat {
std::string describeFile(const std::string& path) { throw Error(path + ": info is not implemented yet"); }
}  // namespace vdbsplat
