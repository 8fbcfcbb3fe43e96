// animation/frame_stats.cpp — flicker, frames.csv rows, switch markers, the SVG plot.
#include "animation/frame_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "metrics/metrics.h"
#include "util/error.h"

namespace vdbsplat::animation {

namespace {

void checkSame(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height)
        throw Error("flicker: image sizes differ: " + sizeText(a) + " vs " + sizeText(b));
    if (a.width < 1 || a.height < 1) throw Error("flicker: empty image");
}

std::string fmt(double v, const char* f = "%.6g") {
    if (std::isnan(v)) return "";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string opt(const std::optional<double>& v, const char* f = "%.6g") { return v ? fmt(*v, f) : ""; }

std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> out;
    size_t start = 0;
    while (true) {
        const size_t c = line.find(',', start);
        out.push_back(line.substr(start, c == std::string::npos ? std::string::npos : c - start));
        if (c == std::string::npos) break;
        start = c + 1;
    }
    return out;
}

bool toDouble(const std::string& s, double& v) {
    if (s.empty()) return false;
    char* end = nullptr;
    v = std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size();
}

bool toCount(const std::string& s, unsigned long long& v) {
    if (s.empty() || s[0] == '-') return false;
    char* end = nullptr;
    v = std::strtoull(s.c_str(), &end, 10);
    return end == s.c_str() + s.size();
}

std::string esc(const std::string& s) {
    std::string o;
    for (const char c : s) {
        if (c == '<') o += "&lt;";
        else if (c == '>') o += "&gt;";
        else if (c == '&') o += "&amp;";
        else if (c == '"') o += "&quot;";
        else o += c;
    }
    return o;
}

}  // namespace

double flicker(const Image& current, const Image& previous, const Image& referenceCurrent,
               const Image& referencePrevious) {
    checkSame(current, previous);
    checkSame(current, referenceCurrent);
    checkSame(current, referencePrevious);
    double sum = 0.0;
    for (int y = 0; y < current.height; ++y) {
        double row = 0.0;
        for (int x = 0; x < current.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double di = displayValue(current.at(x, y)[c]) - displayValue(previous.at(x, y)[c]);
                const double dr = displayValue(referenceCurrent.at(x, y)[c]) - displayValue(referencePrevious.at(x, y)[c]);
                row += std::abs(di - dr);
            }
        sum += row;
    }
    return sum / (3.0 * double(current.pixels.size()));
}

std::string csvHeader(bool reference) {
    std::string h = "frame,time,distance,eye_x,eye_y,eye_z,fov,seconds,points,splats,splat_fraction,switch";
    if (reference) h += ",psnr,flicker,reference_seconds";
    return h;
}

std::string csvRow(const FrameRecord& r, bool reference) {
    std::string s = std::to_string(r.frame) + "," + fmt(r.time, "%.9g") + "," + fmt(r.distance, "%.9g") + "," +
                    fmt(r.eye[0], "%.9g") + "," + fmt(r.eye[1], "%.9g") + "," + fmt(r.eye[2], "%.9g") + "," +
                    fmt(r.fov, "%.9g") + "," + fmt(r.seconds, "%.4f") + "," + std::to_string(r.points) + "," +
                    std::to_string(r.splats) + "," + fmt(r.splatFraction, "%.6f") + "," + r.marker;
    if (reference) s += "," + opt(r.psnr, "%.4f") + "," + opt(r.flicker, "%.6g") + "," + opt(r.referenceSeconds, "%.4f");
    return s;
}

std::optional<FrameRecord> parseCsvRow(const std::string& line, bool reference) {
    const auto f = split(line);
    if (f.size() != (reference ? 15u : 12u)) return std::nullopt;
    FrameRecord r;
    double frame = 0;
    if (!toDouble(f[0], frame) || frame < 0 || frame != std::floor(frame)) return std::nullopt;
    r.frame = (long long)frame;
    if (!toDouble(f[1], r.time)) return std::nullopt;
    if (f[2].empty()) r.distance = std::numeric_limits<double>::quiet_NaN();
    else if (!toDouble(f[2], r.distance)) return std::nullopt;
    for (int i = 0; i < 3; ++i)
        if (!toDouble(f[3 + i], r.eye[i])) return std::nullopt;
    if (!toDouble(f[6], r.fov) || !toDouble(f[7], r.seconds) || !toCount(f[8], r.points) || !toCount(f[9], r.splats) ||
        !toDouble(f[10], r.splatFraction))
        return std::nullopt;
    r.marker = f[11];
    if (reference) {
        double v = 0;
        if (!toDouble(f[12], v)) return std::nullopt;  // every reference row has a PSNR
        r.psnr = v;
        if (!f[13].empty()) {
            if (!toDouble(f[13], v)) return std::nullopt;
            r.flicker = v;
        }
        if (!toDouble(f[14], v)) return std::nullopt;
        r.referenceSeconds = v;
    }
    return r;
}

void markSwitches(std::vector<FrameRecord>& records) {
    for (size_t i = 0; i < records.size(); ++i) {
        records[i].marker.clear();
        if (i == 0) continue;
        const double a = records[i - 1].splatFraction, b = records[i].splatFraction;
        if ((a < 0.5 && b >= 0.5) || (b < 0.5 && a >= 0.5)) records[i].marker = "cross";
        else if (std::abs(b - a) > 0.10) records[i].marker = "step";
    }
}

std::string plotSvg(const std::vector<FrameRecord>& records, const std::string& title) {
    const double W = 800, H = 360, left = 60, right = 70, top = 40, bottom = 50;
    const double pw = W - left - right, ph = H - top - bottom;
    const size_t n = records.size();
    auto xOf = [&](double i) { return left + (n > 1 ? pw * i / double(n - 1) : pw / 2); };
    double pmin = std::numeric_limits<double>::infinity(), pmax = -pmin, fmax = 0.0;
    for (const auto& r : records) {
        if (r.psnr && std::isfinite(*r.psnr)) pmin = std::min(pmin, *r.psnr), pmax = std::max(pmax, *r.psnr);
        if (r.flicker && std::isfinite(*r.flicker)) fmax = std::max(fmax, *r.flicker);
    }
    if (!std::isfinite(pmin)) pmin = 0, pmax = 1;
    pmin = std::floor(pmin / 5) * 5;
    pmax = std::max(pmin + 5, std::ceil(pmax / 5) * 5);
    if (fmax <= 0) fmax = 1e-3;
    fmax *= 1.1;
    auto yP = [&](double p) { return top + ph * (1 - (std::min(p, pmax) - pmin) / (pmax - pmin)); };
    auto yF = [&](double f) { return top + ph * (1 - f / fmax); };
    std::ostringstream s;
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W
      << " " << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
    s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    s << "<text x=\"" << W / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << esc(title) << "</text>\n";
    s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
      << "\" fill=\"none\" stroke=\"#888\"/>\n";
    // Switch markers.
    for (size_t i = 0; i < n; ++i) {
        if (records[i].marker.empty()) continue;
        const bool cross = records[i].marker == "cross";
        s << "<line x1=\"" << xOf(double(i)) << "\" y1=\"" << top << "\" x2=\"" << xOf(double(i)) << "\" y2=\"" << top + ph
          << "\" stroke=\"" << (cross ? "#d62728" : "#ff9896") << "\" stroke-width=\"" << (cross ? 2 : 1)
          << "\"" << (cross ? "" : " stroke-dasharray=\"4 3\"") << "><title>frame " << records[i].frame << ": "
          << records[i].marker << "</title></line>\n";
    }
    // Axes ticks.
    for (int k = 0; k <= 4; ++k) {
        const double p = pmin + (pmax - pmin) * k / 4.0, y = yP(p);
        s << "<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\" fill=\"#1f77b4\">" << fmt(p, "%.1f")
          << "</text>\n";
        const double f = fmax * k / 4.0;
        s << "<text x=\"" << left + pw + 6 << "\" y=\"" << yF(f) + 4 << "\" fill=\"#2ca02c\">" << fmt(f, "%.2g")
          << "</text>\n";
    }
    for (int k = 0; k <= 4 && n > 0; ++k) {
        const double i = std::round(double(n - 1) * k / 4.0);
        s << "<text x=\"" << xOf(i) << "\" y=\"" << top + ph + 16 << "\" text-anchor=\"middle\">"
          << records[size_t(i)].frame << "</text>\n";
    }
    s << "<text x=\"" << left + pw / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">frame</text>\n";
    s << "<text x=\"14\" y=\"" << top + ph / 2 << "\" fill=\"#1f77b4\" transform=\"rotate(-90 14 " << top + ph / 2
      << ")\" text-anchor=\"middle\">PSNR (dB)</text>\n";
    s << "<text x=\"" << W - 10 << "\" y=\"" << top + ph / 2 << "\" fill=\"#2ca02c\" transform=\"rotate(90 " << W - 10
      << " " << top + ph / 2 << ")\" text-anchor=\"middle\">flicker F_t</text>\n";
    auto polyline = [&](auto value, const char* colour, double width, const char* extra) {
        std::string pts;
        for (size_t i = 0; i < n; ++i) {
            const std::optional<double> v = value(records[i]);
            if (!v) continue;
            pts += fmt(xOf(double(i)), "%.2f") + "," + fmt(*v, "%.2f") + " ";
        }
        if (!pts.empty())
            s << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"" << width << "\"" << extra
              << " points=\"" << pts << "\"/>\n";
    };
    polyline([&](const FrameRecord& r) -> std::optional<double> { return top + ph * (1 - r.splatFraction); }, "#aaaaaa",
             1, " stroke-dasharray=\"2 2\"");
    polyline([&](const FrameRecord& r) -> std::optional<double> {
        if (!r.psnr) return std::nullopt;
        return yP(std::isfinite(*r.psnr) ? *r.psnr : pmax);
    }, "#1f77b4", 2, "");
    polyline([&](const FrameRecord& r) -> std::optional<double> {
        if (!r.flicker || !std::isfinite(*r.flicker)) return std::nullopt;
        return yF(*r.flicker);
    }, "#2ca02c", 2, "");
    // Legend.
    const double ly = top + 14;
    const struct {
        const char* colour;
        const char* label;
        const char* dash;
    } items[] = {{"#1f77b4", "PSNR vs reference", ""},
                 {"#2ca02c", "flicker F_t", ""},
                 {"#aaaaaa", "splat fraction (0..1, full height)", "2 2"},
                 {"#d62728", "splat fraction crosses 50%", ""},
                 {"#ff9896", "splat fraction steps > 10 points", "4 3"}};
    double lx = left + 10;
    for (size_t k = 0; k < 5; ++k) {
        const double y = ly + 14.0 * double(k);
        s << "<line x1=\"" << lx << "\" y1=\"" << y << "\" x2=\"" << lx + 20 << "\" y2=\"" << y << "\" stroke=\""
          << items[k].colour << "\" stroke-width=\"2\"" << (*items[k].dash ? std::string(" stroke-dasharray=\"") + items[k].dash + "\"" : "")
          << "/><text x=\"" << lx + 26 << "\" y=\"" << y + 4 << "\">" << esc(items[k].label) << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

}  // namespace vdbsplat::animation
