// volume/transfer_function.cpp — placeholder grey ramp until the transfer-function work lands.
#include "volume/transfer_function.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace vdbsplat {

ClassificationTable::ClassificationTable(std::vector<Classified> entries, float valueMin, float valueMax)
    : entries_(std::move(entries)), valueMin_(valueMin),
      scale_(valueMax > valueMin ? float(kSize - 1) / (valueMax - valueMin) : 0.f) {}

Classified ClassificationTable::operator()(float value) const {
    if (!std::isfinite(value) || entries_.empty()) return {};
    const float x = std::clamp((value - valueMin_) * scale_, 0.f, float(kSize - 1));
    const int i = std::min(int(x), kSize - 2);
    const float t = x - float(i);
    const Classified& a = entries_[i];
    const Classified& b = entries_[i + 1];
    return {a.color + t * (b.color - a.color), a.sigma + t * (b.sigma - a.sigma)};
}

bool ClassificationTable::empty() const {
    return std::none_of(entries_.begin(), entries_.end(), [](const Classified& c) { return c.sigma > 0.f; });
}

TransferFunction TransferFunction::preset(const std::string& name) {
    if (name != "grey") throw Error("unknown transfer function preset '" + name + "'");
    TransferFunction tf;
    tf.name_ = "grey";
    tf.colors_ = {{0.f, glm::vec3(0.f)}, {1.f, glm::vec3(1.f)}};
    tf.extinction_ = {{0.f, 0.f}, {1.f, 0.5f}};
    return tf;
}
std::vector<std::string> TransferFunction::presetNames() { return {"grey"}; }
TransferFunction TransferFunction::fromSpec(const std::string& spec) { return preset(spec); }
TransferFunction TransferFunction::fromJson(const std::string&, const std::string& origin) {
    throw Error(origin + ": JSON transfer functions are not implemented yet");
}

Classified TransferFunction::evaluate(float x) const {
    x = std::clamp(x, 0.f, 1.f);
    return {glm::vec3(x), 0.5f * x};
}

ClassificationTable TransferFunction::bake(float valueMin, float valueMax, double voxelSize) const {
    std::vector<Classified> e(ClassificationTable::kSize);
    for (int i = 0; i < ClassificationTable::kSize; ++i) {
        e[i] = evaluate(float(i) / (ClassificationTable::kSize - 1));
        if (worldUnits_) e[i].sigma *= float(voxelSize);
    }
    return ClassificationTable(std::move(e), valueMin, valueMax);
}

std::string TransferFunction::toJson() const { return "{\"name\":\"" + name_ + "\"}"; }

}  // namespace vdbsplat
