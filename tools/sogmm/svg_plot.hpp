// Line charts written as SVG text (no plotting dependency): `sogmm map`
// plots components and times against frame with it.
#pragma once

#include <string>
#include <vector>

namespace sogmm::tools {

/// One line of a chart: y values at the chart's x values.
struct PlotSeries {
  std::string name;
  std::string color;  ///< SVG color, e.g. "#1f77b4"
  std::vector<double> y;
};

/// One chart: a title, the y axis label and its lines (y axis from 0 to the
/// largest finite value).
struct PlotPanel {
  std::string title;
  std::string y_label;
  std::vector<PlotSeries> series;
};

/// A standalone SVG document with the panels stacked vertically, sharing the
/// x values (ascending) and the x axis label; each panel has a legend and
/// min/max tick labels. Non-finite values are skipped.
std::string svg_line_charts(const std::vector<double>& x, const std::string& x_label,
                            const std::vector<PlotPanel>& panels);

}  // namespace sogmm::tools
