#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sogmm::tools {

namespace {
constexpr double kWidth = 800, kPanelHeight = 260, kLeft = 70, kRight = 20, kTop = 30, kBottom = 40;

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

std::string fmt(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

std::string text(double x, double y, const std::string& s, const char* anchor = "start") {
  return "<text x=\"" + fmt("%.1f", x) + "\" y=\"" + fmt("%.1f", y) + "\" text-anchor=\"" + anchor + "\">" +
         escape(s) + "</text>\n";
}
}  // namespace

std::string svg_line_charts(const std::vector<double>& x, const std::string& x_label,
                            const std::vector<PlotPanel>& panels) {
  const double height = kPanelHeight * static_cast<double>(panels.size());
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fmt("%.0f", kWidth) + "\" height=\"" +
                    fmt("%.0f", height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n" +
                    "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  double x_lo = 0, x_hi = 1;
  if (!x.empty()) {
    x_lo = x.front();
    x_hi = std::max(x.back(), x_lo + 1);
  }
  const double plot_w = kWidth - kLeft - kRight, plot_h = kPanelHeight - kTop - kBottom;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const PlotPanel& panel = panels[p];
    const double top = kPanelHeight * static_cast<double>(p) + kTop, bottom = top + plot_h;
    double y_hi = 0;
    for (const PlotSeries& s : panel.series)
      for (double v : s.y)
        if (std::isfinite(v)) y_hi = std::max(y_hi, v);
    if (y_hi <= 0) y_hi = 1;
    svg += text(kLeft, top - 10, panel.title);
    svg += "<rect x=\"" + fmt("%.1f", kLeft) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" + fmt("%.1f", plot_w) +
           "\" height=\"" + fmt("%.1f", plot_h) + "\" fill=\"none\" stroke=\"#888\"/>\n";
    svg += text(kLeft - 5, bottom + 4, "0", "end") + text(kLeft - 5, top + 4, fmt("%.4g", y_hi), "end");
    svg += text(kLeft, bottom + 16, fmt("%.0f", x_lo), "middle") +
           text(kLeft + plot_w, bottom + 16, fmt("%.0f", x_hi), "middle");
    svg += text(kLeft + plot_w / 2, bottom + 32, x_label, "middle");
    svg += "<text transform=\"translate(" + fmt("%.1f", kLeft - 40) + "," + fmt("%.1f", (top + bottom) / 2) +
           ") rotate(-90)\" text-anchor=\"middle\">" + escape(panel.y_label) + "</text>\n";
    for (std::size_t k = 0; k < panel.series.size(); ++k) {
      const PlotSeries& s = panel.series[k];
      std::string points;
      for (std::size_t i = 0; i < x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.y[i]) || !std::isfinite(x[i])) continue;
        const double px = kLeft + (x[i] - x_lo) / (x_hi - x_lo) * plot_w;
        const double py = bottom - std::clamp(s.y[i] / y_hi, 0.0, 1.0) * plot_h;
        points += fmt("%.1f", px) + "," + fmt("%.1f", py) + " ";
      }
      svg += "<polyline fill=\"none\" stroke=\"" + s.color + "\" stroke-width=\"1.5\" points=\"" + points + "\"/>\n";
      const double ly = top + 14 + 14 * static_cast<double>(k);
      svg += "<line x1=\"" + fmt("%.1f", kLeft + 10) + "\" y1=\"" + fmt("%.1f", ly - 4) + "\" x2=\"" +
             fmt("%.1f", kLeft + 30) + "\" y2=\"" + fmt("%.1f", ly - 4) + "\" stroke=\"" + s.color +
             "\" stroke-width=\"2\"/>\n";
      svg += text(kLeft + 35, ly, s.name);
    }
  }
  return svg + "</svg>\n";
}

}  // namespace sogmm::tools
