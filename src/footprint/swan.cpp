// footprint/swan.cpp — Swan et al. 1997's uniform footprint stretch (see swan.h).
#include "footprint/swan.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "footprint/kernel.h"

namespace vdbsplat {

double swanStretch(const SphereProjection& e, double prefilterVariance, const KernelShape& kernel) {
    const double minorSigma = std::min(e.a, e.b) * kernel.sigma() / kernel.radius();  // px
    const double filterSigma = std::sqrt(std::max(prefilterVariance, 0.0));
    return minorSigma > 0.0 ? std::max(1.0, filterSigma / minorSigma) : 1.0;
}

ScreenKernel makeSwanKernel(const SphereProjection& e, double prefilterVariance, const KernelShape& kernel) {
    if (!e.isEllipse())
        throw std::invalid_argument(std::string("makeSwanKernel: sphere is '") + sphereClassName(e.kind) +
                                    "', not an ellipse");
    const double s = swanStretch(e, prefilterVariance, kernel);
    ScreenKernel k = makeScreenKernel(e, 0.0);  // the exact ellipse, amplitude 1
    k.a *= s, k.b *= s;
    k.conic /= s * s;
    k.amplitude = 1.0 / (s * s);  // Swan et al. 1997: height scaled by 1/s² keeps the 2D integral
    k.pullback = glm::dmat2(1.0 / s);
    k.bounds = {k.centre + (k.bounds.lo - k.centre) * s, k.centre + (k.bounds.hi - k.centre) * s};
    return k;
}

}  // namespace vdbsplat
