// study/report.cpp — metrics.csv, metrics.json, the SVG plots and index.html (see report.h).
#include "study/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

namespace vdbsplat::study {

namespace {

std::string fmt(double v, const char* format) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break (a grid name can).
std::string csvField(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string q = "\"";
    for (const char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

std::string psnrText(double psnr) { return std::isfinite(psnr) ? fmt(psnr, "%.2f") : "inf"; }

double splatFraction(const ModeResult& m) {
    const uint64_t drawn = m.points + m.splats;
    return drawn ? double(m.splats) / double(drawn) : 0.0;
}

/// Every (volume, kernel, view, mode) in report order.
template <class F>
void forEachRow(const StudyResult& study, F&& f) {
    for (const VolumeResult& vol : study.volumes)
        for (const KernelResult& k : vol.kernels)
            for (const ViewResult& v : k.views)
                for (const ModeResult& m : v.modes) f(vol, k, v, m);
}

std::string zoomText(double zoom) {
    for (int k = 1; k <= 16; k *= 2) {
        if (std::abs(zoom - double(k)) < 1e-9) return std::to_string(k) + "×";
        if (std::abs(zoom - 1.0 / double(k)) < 1e-9) return "1/" + std::to_string(k) + "×";
    }
    return fmt(zoom, "%.3g") + "×";
}

}  // namespace

std::string htmlEscape(const std::string& text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string modeColour(size_t i) {
    static const char* palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf"};
    return palette[i % (sizeof palette / sizeof *palette)];
}

// ---- metrics.csv / metrics.json ---------------------------------------------------------

std::string csvHeader() {
    return "volume,grid,tf,kernel,view,distance,zoom,mode,psnr_db,ssim,rmse,max_abs_error,seconds,reference_seconds,"
           "points,splats,splat_fraction,image,error_image";
}

std::string metricsCsv(const StudyResult& study) {
    std::string out = csvHeader() + "\n";
    forEachRow(study, [&](const VolumeResult& vol, const KernelResult& k, const ViewResult& v, const ModeResult& m) {
        out += vol.id + "," + csvField(vol.grid) + "," + csvField(vol.tf) + "," + k.kernel + "," + v.view.id + "," + fmt(v.view.distance, "%.9g") + "," +
               fmt(v.view.zoom(), "%.9g") + "," + m.mode + "," + psnrText(m.metrics.psnr) + "," +
               fmt(m.metrics.ssim, "%.6f") + "," + fmt(m.metrics.rmse, "%.6g") + "," +
               fmt(m.metrics.maxAbsError, "%.6g") + "," + fmt(m.seconds, "%.6f") + "," +
               fmt(v.referenceSeconds, "%.6f") + "," + std::to_string(m.points) + "," + std::to_string(m.splats) + "," +
               fmt(splatFraction(m), "%.6f") + "," + m.image + "," + m.errorImage + "\n";
    });
    return out;
}

nlohmann::ordered_json metricsJson(const StudyResult& study) {
    nlohmann::ordered_json j;
    j["command"] = study.command;
    j["width"] = study.width;
    j["height"] = study.height;
    j["reference_spp"] = study.spp;
    j["tf"] = study.tf;
    j["modes"] = study.modes;
    j["kernels"] = study.kernels;
    j["settings"] = study.settings;
    nlohmann::ordered_json volumes = nlohmann::ordered_json::array();
    for (const VolumeResult& vol : study.volumes)
        volumes.push_back({{"id", vol.id}, {"path", vol.path}, {"grid", vol.grid}, {"tf", vol.tf},
                           {"active_voxels", vol.activeVoxels}});
    j["volumes"] = volumes;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    forEachRow(study, [&](const VolumeResult& vol, const KernelResult& k, const ViewResult& v, const ModeResult& m) {
        nlohmann::ordered_json r;
        r["volume"] = vol.id;
        r["grid"] = vol.grid;
        r["tf"] = vol.tf;
        r["kernel"] = k.kernel;
        r["view"] = v.view.id;
        r["view_label"] = v.view.label;
        r["distance"] = v.view.distance;
        r["zoom"] = v.view.zoom();
        r["mode"] = m.mode;
        r["psnr_db"] = std::isfinite(m.metrics.psnr) ? nlohmann::ordered_json(m.metrics.psnr) : nlohmann::ordered_json(nullptr);
        r["ssim"] = m.metrics.ssim;
        r["rmse"] = m.metrics.rmse;
        r["max_abs_error"] = m.metrics.maxAbsError;
        r["seconds"] = m.seconds;
        r["reference_seconds"] = v.referenceSeconds;
        r["points"] = m.points;
        r["splats"] = m.splats;
        r["splat_fraction"] = splatFraction(m);
        r["image"] = m.image;
        r["error_image"] = m.errorImage;
        r["crop_image"] = m.cropImage;
        r["reference_image"] = v.referenceImage;
        rows.push_back(r);
    });
    j["rows"] = rows;
    return j;
}

// ---- plots ------------------------------------------------------------------------------

std::string plotSvg(const Plot& plot) {
    const double W = 420, H = 280, left = 58, right = 12, top = 30, bottom = 66;
    const double pw = W - left - right, ph = H - top - bottom;
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
    std::vector<double> xs;
    auto yv = [&](double y) { return plot.logY ? std::log10(y) : y; };
    for (const Series& s : plot.series)
        for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
            if (!(s.x[i] > 0) || !std::isfinite(s.y[i]) || (plot.logY && !(s.y[i] > 0))) continue;
            const double lx = std::log2(s.x[i]);
            xmin = std::min(xmin, lx), xmax = std::max(xmax, lx);
            ymin = std::min(ymin, yv(s.y[i])), ymax = std::max(ymax, yv(s.y[i]));
            if (std::find(xs.begin(), xs.end(), s.x[i]) == xs.end()) xs.push_back(s.x[i]);
        }
    if (!std::isfinite(xmin)) xmin = -1, xmax = 1, ymin = 0, ymax = 1;
    if (xmax - xmin < 1e-9) xmin -= 1, xmax += 1;
    if (plot.logY) {
        ymin = std::floor(ymin * 2) / 2, ymax = std::ceil(ymax * 2) / 2;
        if (ymax - ymin < 0.5) ymax = ymin + 0.5;
    } else {
        const double span = std::max(ymax - ymin, 1e-6), pad = 0.08 * span;
        ymin -= pad, ymax = std::min(ymax + pad, std::max(plot.yCap, ymax));
    }
    const double xpad = 0.06 * (xmax - xmin);
    xmin -= xpad, xmax += xpad;
    auto X = [&](double x) { return left + pw * (std::log2(x) - xmin) / (xmax - xmin); };
    auto Y = [&](double y) { return top + ph * (1 - (yv(y) - ymin) / (ymax - ymin)); };

    std::ostringstream s;
    s << "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
      << "\" viewBox=\"0 0 " << W << " " << H << "\" font-family=\"sans-serif\" font-size=\"11\" role=\"img\">\n";
    s << "<title>" << htmlEscape(plot.title) << "</title>\n";
    s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    s << "<text x=\"" << W / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">" << htmlEscape(plot.title)
      << "</text>\n";
    s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
      << "\" fill=\"none\" stroke=\"#888\"/>\n";
    // y ticks: five even ones, or the decades and half decades of a log axis.
    std::vector<double> yticks;
    if (plot.logY) {
        for (double e = std::ceil(ymin); e <= ymax + 1e-9; e += 1) yticks.push_back(std::pow(10.0, e));
        if (yticks.size() < 2)
            for (double e = std::ceil(ymin * 2) / 2; e <= ymax + 1e-9; e += 0.5) yticks.push_back(std::pow(10.0, e));
    } else {
        // Round steps (1, 2 or 5 times a power of ten), about four of them.
        const double raw = (ymax - ymin) / 4.0, mag = std::pow(10.0, std::floor(std::log10(raw)));
        const double step = raw / mag < 1.5 ? mag : raw / mag < 3.5 ? 2 * mag : raw / mag < 7.5 ? 5 * mag : 10 * mag;
        for (double t = std::ceil(ymin / step) * step; t <= ymax + 1e-12; t += step) yticks.push_back(std::abs(t) < 1e-12 ? 0.0 : t);
    }
    for (const double t : yticks) {
        const double y = Y(t);
        s << "<line x1=\"" << left << "\" y1=\"" << fmt(y, "%.2f") << "\" x2=\"" << left + pw << "\" y2=\""
          << fmt(y, "%.2f") << "\" stroke=\"#eee\"/>\n";
        s << "<text x=\"" << left - 5 << "\" y=\"" << fmt(y + 4, "%.2f") << "\" text-anchor=\"end\">"
          << fmt(t, plot.logY ? "%.3g" : "%.6g") << "</text>\n";
    }
    std::sort(xs.begin(), xs.end());
    double lastLabel = -1e9;
    for (const double x : xs) {
        const bool label = X(x) - lastLabel >= 34;  // crowded ticks (2× beside 2.86×) keep only their line
        if (label) lastLabel = X(x);
        s << "<line x1=\"" << fmt(X(x), "%.2f") << "\" y1=\"" << top << "\" x2=\"" << fmt(X(x), "%.2f") << "\" y2=\""
          << top + ph << "\" stroke=\"#eee\"/>\n";
        if (!label) continue;
        s << "<text x=\"" << fmt(X(x), "%.2f") << "\" y=\"" << top + ph + 14 << "\" text-anchor=\"middle\">"
          << htmlEscape(zoomText(x)) << "</text>\n";
    }
    s << "<text x=\"" << left + pw / 2 << "\" y=\"" << top + ph + 30 << "\" text-anchor=\"middle\">"
      << htmlEscape(plot.xLabel) << "</text>\n";
    s << "<text x=\"13\" y=\"" << top + ph / 2 << "\" transform=\"rotate(-90 13 " << top + ph / 2
      << ")\" text-anchor=\"middle\">" << htmlEscape(plot.yLabel) << "</text>\n";
    // Lines, markers, legend.
    double lx = left;
    const double ly = H - 12;
    for (size_t si = 0; si < plot.series.size(); ++si) {
        const Series& ser = plot.series[si];
        // Earlier series wider, so a line lying on another (hybrid on point or splat) still shows.
        const double width = 1.5 + 1.5 * double(plot.series.size() - 1 - si);
        std::string pts;
        std::vector<std::pair<double, double>> sorted;
        for (size_t i = 0; i < ser.x.size() && i < ser.y.size(); ++i)
            if (ser.x[i] > 0 && std::isfinite(ser.y[i]) && (!plot.logY || ser.y[i] > 0)) sorted.emplace_back(ser.x[i], ser.y[i]);
        std::sort(sorted.begin(), sorted.end());
        for (const auto& [x, y] : sorted) pts += fmt(X(x), "%.2f") + "," + fmt(Y(y), "%.2f") + " ";
        const std::string dash = ser.dashed ? " stroke-dasharray=\"5 3\"" : "";
        if (!pts.empty())
            s << "<polyline class=\"series\" data-name=\"" << htmlEscape(ser.name) << "\" fill=\"none\" stroke=\""
              << ser.colour << "\" stroke-width=\"" << width << "\" stroke-opacity=\"0.85\"" << dash << " points=\"" << pts
              << "\"/>\n";
        for (const auto& [x, y] : sorted)
            s << "<circle cx=\"" << fmt(X(x), "%.2f") << "\" cy=\"" << fmt(Y(y), "%.2f") << "\" r=\"" << 1.5 + width / 2
              << "\" fill=\""
              << ser.colour << "\"><title>" << htmlEscape(ser.name) << " at zoom " << htmlEscape(zoomText(x)) << ": "
              << fmt(y, "%.4g") << "</title></circle>\n";
        s << "<line x1=\"" << lx << "\" y1=\"" << ly - 4 << "\" x2=\"" << lx + 16 << "\" y2=\"" << ly - 4
          << "\" stroke=\"" << ser.colour << "\" stroke-width=\"2\"" << dash << "/>\n";
        s << "<text x=\"" << lx + 19 << "\" y=\"" << ly << "\">" << htmlEscape(ser.name) << "</text>\n";
        lx += 26 + 6.5 * double(ser.name.size());
    }
    s << "</svg>\n";
    return s.str();
}

std::string colourBarSvg() {
    const double W = 236, H = 44, left = 16, barW = 200, barH = 14;
    std::ostringstream s;
    s << "<svg class=\"colourbar\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
      << "\" viewBox=\"0 0 " << W << " " << H << "\" font-family=\"sans-serif\" font-size=\"10\" role=\"img\">\n";
    s << "<title>error colour scale (mean |display difference| over RGB, log scale)</title>\n";
    s << "<defs><linearGradient id=\"heat\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">";
    for (int k = 0; k <= 16; ++k)
        s << "<stop offset=\"" << fmt(k / 16.0, "%.4f") << "\" stop-color=\"" << heatHex(k / 16.0) << "\"/>";
    s << "</linearGradient></defs>\n";
    s << "<rect x=\"" << left << "\" y=\"4\" width=\"" << barW << "\" height=\"" << barH
      << "\" fill=\"url(#heat)\" stroke=\"#666\"/>\n";
    for (const double e : {0.001, 0.003, 0.01, 0.03, 0.1, 0.3}) {
        const double x = left + barW * heatPosition(e);
        s << "<line x1=\"" << fmt(x, "%.2f") << "\" y1=\"" << 4 + barH << "\" x2=\"" << fmt(x, "%.2f") << "\" y2=\""
          << 8 + barH << "\" stroke=\"#333\"/>\n";
        s << "<text x=\"" << fmt(x, "%.2f") << "\" y=\"" << 19 + barH << "\" text-anchor=\"middle\">"
          << (e == 0.3 ? "≥0.3" : e == 0.001 ? "≤0.001" : fmt(e, "%g")) << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

// ---- index.html -------------------------------------------------------------------------

namespace {

const char* kCss = R"(body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1600px}
h1{margin-bottom:.2em}h2{border-bottom:2px solid #ccc;padding-bottom:.2em;margin-top:2em}
h3{margin-top:1.5em}h4{margin:1.2em 0 .4em}
.meta{color:#555;font-size:.9em}code{background:#f4f4f4;padding:.1em .3em;word-break:break-all}
.methods{display:flex;flex-wrap:wrap;gap:10px}
.methods figure{margin:0;padding:6px;border:1px solid #ddd;border-radius:4px;background:#fafafa}
.methods figcaption{font-size:.8em;line-height:1.3;max-width:256px}
.methods img.render,.methods img.heat{display:block;width:256px;height:auto;image-rendering:auto}
.methods img.crop{display:block;width:128px;height:128px;image-rendering:pixelated;margin-top:4px}
.methods .best{font-weight:bold;color:#0a6}
.plots{display:flex;flex-wrap:wrap;gap:10px}
table.metrics{border-collapse:collapse;font-size:.85em;margin-top:1em}
table.metrics th,table.metrics td{border:1px solid #ccc;padding:2px 6px;text-align:right}
table.metrics th{background:#eee;position:sticky;top:0}
table.metrics td.t{text-align:left}table.metrics tr.first td{border-top:2px solid #888}
table.metrics td.best{font-weight:bold;color:#0a6}
#selfcheck{margin-top:2em;font-size:.85em;color:#555})";

/// The page's own check: how many images loaded, written into #selfcheck (read by the tests).
const char* kScript = R"(window.addEventListener('load', function () {
  var imgs = document.images, ok = 0, missing = [];
  for (var i = 0; i < imgs.length; ++i) {
    if (imgs[i].complete && imgs[i].naturalWidth > 0) ++ok; else missing.push(imgs[i].getAttribute('src'));
  }
  var el = document.getElementById('selfcheck');
  el.setAttribute('data-images', imgs.length);
  el.setAttribute('data-loaded', ok);
  el.setAttribute('data-tables', document.querySelectorAll('table.metrics tbody tr').length);
  el.setAttribute('data-plots', document.querySelectorAll('svg.plot polyline.series').length);
  el.setAttribute('data-status', ok === imgs.length ? 'ok' : 'missing');
  el.textContent = ok === imgs.length ? 'Report check: all ' + imgs.length + ' images loaded.'
    : 'Report check: ' + (imgs.length - ok) + ' of ' + imgs.length + ' images did not load: ' + missing.join(', ');
});)";

/// The best PSNR among the modes of a view (NaN when none).
double bestPsnr(const ViewResult& v) {
    double best = -std::numeric_limits<double>::infinity();
    for (const ModeResult& m : v.modes) best = std::max(best, m.metrics.psnr);
    return v.modes.empty() ? std::numeric_limits<double>::quiet_NaN() : best;
}

std::string img(const std::string& cls, const std::string& src, const std::string& alt) {
    return "<img class=\"" + cls + "\" src=\"" + htmlEscape(src) + "\" alt=\"" + htmlEscape(alt) + "\">";
}

std::string viewHtml(const StudyResult& study, const ViewResult& v) {
    std::ostringstream s;
    s << "<h4>" << htmlEscape(v.view.label);
    if (v.view.label.rfind("zoom ", 0) != 0) s << " — zoom " << htmlEscape(zoomText(v.view.zoom()));  // the ladder's say it
    s << "</h4>\n";
    s << "<div class=\"methods\">\n<figure>" << img("render", v.referenceImage, "reference") << "<figcaption><b>reference</b>, "
      << study.spp << " rays/pixel, " << fmt(v.referenceSeconds, "%.3g") << " s</figcaption>" << colourBarSvg()
      << "<figcaption>error scale of the maps below each mode</figcaption>"
      << img("crop", v.referenceCrop, "reference crop") << "<figcaption>crop " << v.crop.size << "×" << v.crop.size
      << " px at (" << v.crop.x << ", " << v.crop.y << "), the window where the modes err most</figcaption></figure>\n";
    const double best = bestPsnr(v);
    for (const ModeResult& m : v.modes) {
        const bool isBest = m.metrics.psnr == best;
        s << "<figure>" << img("render", m.image, m.mode) << "<figcaption><b>" << htmlEscape(m.mode) << "</b>: <span"
          << (isBest ? " class=\"best\"" : "") << ">" << psnrText(m.metrics.psnr) << " dB</span>, SSIM "
          << fmt(m.metrics.ssim, "%.4f") << ", " << fmt(m.seconds, "%.3g") << " s, splats "
          << fmt(100.0 * splatFraction(m), "%.0f") << "%</figcaption>" << img("heat", m.errorImage, m.mode + " error")
          << img("crop", m.cropImage, m.mode + " crop") << "</figure>\n";
    }
    s << "</div>\n";
    return s.str();
}

std::string plotsHtml(const StudyResult& study, const VolumeResult& vol, const KernelResult& k) {
    Plot psnr{vol.id + " — PSNR against the reference", "zoom (1 = framed)", "PSNR (dB)", false, {}};
    Plot ssim{vol.id + " — SSIM against the reference", "zoom (1 = framed)", "SSIM", false, {}, 1.0};
    Plot time{vol.id + " — render time", "zoom (1 = framed)", "seconds (log)", true, {}};
    for (size_t mi = 0; mi < study.modes.size(); ++mi) {
        Series p{study.modes[mi], modeColour(mi), false, {}, {}}, q = p, t = p;
        for (const ViewResult& v : k.views)
            for (const ModeResult& m : v.modes)
                if (m.mode == study.modes[mi]) {
                    p.x.push_back(v.view.zoom()), p.y.push_back(m.metrics.psnr);
                    q.x.push_back(v.view.zoom()), q.y.push_back(m.metrics.ssim);
                    t.x.push_back(v.view.zoom()), t.y.push_back(m.seconds);
                }
        psnr.series.push_back(p), ssim.series.push_back(q), time.series.push_back(t);
    }
    Series ref{"reference", "#555555", true, {}, {}};
    for (const ViewResult& v : k.views) ref.x.push_back(v.view.zoom()), ref.y.push_back(v.referenceSeconds);
    time.series.push_back(ref);
    return "<div class=\"plots\">\n" + plotSvg(psnr) + plotSvg(ssim) + plotSvg(time) + "</div>\n";
}

std::string tableHtml(const StudyResult& study) {
    std::ostringstream s;
    s << "<table class=\"metrics\">\n<thead><tr><th>volume</th><th>kernel</th><th>view</th><th>zoom</th><th>mode</th>"
         "<th>PSNR (dB)</th><th>SSIM</th><th>RMSE</th><th>max error</th><th>time (s)</th><th>reference (s)</th>"
         "<th>splats</th></tr></thead>\n<tbody>\n";
    for (const VolumeResult& vol : study.volumes)
        for (const KernelResult& k : vol.kernels)
            for (const ViewResult& v : k.views) {
                const double best = bestPsnr(v);
                for (size_t i = 0; i < v.modes.size(); ++i) {
                    const ModeResult& m = v.modes[i];
                    s << "<tr" << (i == 0 ? " class=\"first\"" : "") << "><td class=\"t\">" << htmlEscape(vol.id)
                      << "</td><td class=\"t\">" << htmlEscape(k.kernel) << "</td><td class=\"t\">"
                      << htmlEscape(v.view.label) << "</td><td>" << htmlEscape(zoomText(v.view.zoom()))
                      << "</td><td class=\"t\">" << htmlEscape(m.mode) << "</td><td"
                      << (m.metrics.psnr == best ? " class=\"best\"" : "") << ">" << psnrText(m.metrics.psnr)
                      << "</td><td>" << fmt(m.metrics.ssim, "%.4f") << "</td><td>" << fmt(m.metrics.rmse, "%.2e")
                      << "</td><td>" << fmt(m.metrics.maxAbsError, "%.3f") << "</td><td>" << fmt(m.seconds, "%.3f")
                      << "</td><td>" << fmt(v.referenceSeconds, "%.2f") << "</td><td>"
                      << fmt(100.0 * splatFraction(m), "%.0f") << "%</td></tr>\n";
                }
            }
    s << "</tbody></table>\n";
    return s.str();
}

}  // namespace

std::string reportHtml(const StudyResult& study) {
    std::ostringstream s;
    s << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<title>vdbsplat study</title>\n<style>\n"
      << kCss << "\n</style>\n</head>\n<body>\n<h1>vdbsplat study</h1>\n";
    std::string modes, kernels;
    for (const auto& m : study.modes) modes += (modes.empty() ? "" : ", ") + m;
    for (const auto& k : study.kernels) kernels += (kernels.empty() ? "" : ", ") + k;
    s << "<p class=\"meta\">" << study.width << "×" << study.height << " pixels, reference " << study.spp
      << " rays per pixel, transfer function <code>" << htmlEscape(study.tf) << "</code>; modes " << htmlEscape(modes)
      << "; kernels " << htmlEscape(kernels) << ". Metrics on display values (sRGB over black) against the "
      << "reference of the same kernel, camera and prefilter; times are one render each on this machine, as `vdbsplat render` times it. "
      << "Files: <a href=\"metrics.csv\">metrics.csv</a>, <a href=\"metrics.json\">metrics.json</a>, "
      << "<a href=\"command.txt\">command.txt</a>.</p>\n<p class=\"meta\">Made by <code>" << htmlEscape(study.command)
      << "</code></p>\n<nav><p>";
    for (const VolumeResult& vol : study.volumes)
        s << "<a href=\"#vol-" << htmlEscape(vol.id) << "\">" << htmlEscape(vol.id) << "</a> · ";
    s << "<a href=\"#table\">metrics table</a></p></nav>\n";
    for (const VolumeResult& vol : study.volumes) {
        s << "<section id=\"vol-" << htmlEscape(vol.id) << "\">\n<h2>" << htmlEscape(vol.id) << "</h2>\n<p class=\"meta\">"
          << htmlEscape(vol.path) << ", grid '" << htmlEscape(vol.grid) << "', " << vol.activeVoxels
          << " active voxels, transfer function <code>" << htmlEscape(vol.tf) << "</code></p>\n";
        for (const KernelResult& k : vol.kernels) {
            s << "<h3>kernel " << htmlEscape(k.kernel) << "</h3>\n" << plotsHtml(study, vol, k);
            for (const ViewResult& v : k.views) s << viewHtml(study, v);
        }
        s << "</section>\n";
    }
    s << "<h2 id=\"table\">Metrics</h2>\n<p class=\"meta\">Best PSNR of each view in bold green. The same numbers "
         "are in metrics.csv.</p>\n"
      << tableHtml(study);
    s << "<p id=\"selfcheck\" data-status=\"pending\">Report check: needs JavaScript.</p>\n<script>\n" << kScript
      << "\n</script>\n</body>\n</html>\n";
    return s.str();
}

}  // namespace vdbsplat::study
