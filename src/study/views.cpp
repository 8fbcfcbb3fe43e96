// study/views.cpp — standard views, zoom ladder, list parsing and ids (see views.h).
#include "study/views.h"
#include "util/fnv1a.h"

#include <cstdio>

#include "util/error.h"

namespace vdbsplat::study {

namespace {

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace

std::vector<View> standardViews() {
    return {{viewId(8.0), "far (distance 8)", 8.0},
            {viewId(1.0), "framed (distance 1)", 1.0},
            {viewId(0.35), "close (distance 0.35)", 0.35}};
}

std::vector<View> zoomLadder(double base) {
    if (!(base >= 1e-3 && base < 1e5)) throw Error("--base: must be a number in [0.001, 1e5), got " + number(base));
    const struct {
        double zoom;
        const char* text;
    } steps[] = {{0.125, "1/8"}, {0.25, "1/4"}, {0.5, "1/2"}, {1.0, "1"}, {2.0, "2"}, {4.0, "4"}, {8.0, "8"}};
    std::vector<View> views;
    for (const auto& s : steps) {
        const double d = base / s.zoom;
        views.push_back({viewId(d), std::string("zoom ") + s.text + "x (distance " + number(d) + ")", d});
    }
    return views;
}

View viewAt(double distance) { return {viewId(distance), "distance " + number(distance), distance}; }

std::vector<View> withoutRepeats(const std::vector<View>& views) {
    std::vector<View> out;
    for (const View& v : views) {
        bool seen = false;
        for (const View& o : out) seen = seen || o.id == v.id;
        if (!seen) out.push_back(v);
    }
    return out;
}

std::string viewId(double distance) {
    std::string id = "d";
    for (const char c : number(distance)) id += c == '.' ? '_' : c == '-' ? 'm' : c == '+' ? 'p' : c;
    return id;
}

std::string safeId(const std::string& text) {
    std::string id;
    for (const char c : text) {
        if (id.size() >= 48) break;
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
        id += ok ? c : '_';
    }
    return id.empty() || id.find_first_not_of('_') == std::string::npos ? "volume" : id;
}

std::string fnv1a(const std::string& text) { return fnv1aHex(text); }

}  // namespace vdbsplat::study
