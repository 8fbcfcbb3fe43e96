// footprint/reindex.cpp — d(i, α) (DESIGN §3; see reindex.h for the derivation).
#include "footprint/reindex.h"

#include <cmath>

namespace vdbsplat {

double reindex2(double i2, double alpha) {
    const double s = std::sin(alpha), c = std::cos(alpha);
    // sin²(atan t) = t²/(1+t²) with t = i·tanα, divided by sin²α.
    return i2 / (c * c + i2 * s * s);
}

double reindex(double i, double alpha) {
    if (alpha == 0.0) return i;
    return std::sin(std::atan(i * std::tan(alpha))) / std::sin(alpha);  // DESIGN §3 as printed
}

double reindexMisprinted(double i, double alpha) {
    if (alpha == 0.0) return i;
    return std::sin(std::atan(i * std::tan(alpha))) / std::tan(alpha);
}

}  // namespace vdbsplat
