// Line plots as standalone SVG files for sweeps and run-time figures: panels stacked vertically
// that share the x axis (linear or log), "nice" ticks, a left and an optional right y axis per
// panel, a legend per panel (docs/REPORTS.md).
//
//   roiflow::report::Plot plot;
//   plot.title = "Error vs patch size";
//   plot.x_label = "patch size (px)";
//   roiflow::report::PlotPanel& p = plot.panels.emplace_back();
//   p.y_label = "AAE (deg)";
//   p.y2_label = "EPE (px)";  // a second y axis, on the right
//   p.series.push_back({"AAE", {3, 10, 17}, {5.1, 3.9, 4.2}});
//   p.series.push_back({"EPE", {3, 10, 17}, {0.4, 0.28, 0.3}, roiflow::report::PlotAxis::Right});
//   roiflow::report::write_plot_svg("out/patch.svg", plot);  // atomically
#pragma once

#include <string>
#include <vector>

namespace roiflow::report {

enum class PlotAxis { Left, Right };

struct PlotSeries {
  std::string name;  // legend text
  std::vector<double> x;
  std::vector<double> y;
  PlotAxis axis = PlotAxis::Left;  // Right: scaled on the panel's second axis (needs y2_label)
  bool markers = true;             // false: the line only (series of hundreds of points)
};

struct PlotPanel {
  std::string y_label;   // with units, e.g. "time (ms per pair)"
  std::string y2_label;  // right axis label; empty = no right axis
  std::vector<PlotSeries> series;
  bool y_from_zero = false;  // include 0 in the y range(s)
};

struct Plot {
  std::string title;
  std::string x_label;  // with units
  bool x_log = false;   // log10 x axis
  std::vector<PlotPanel> panels;
  int width = 760;         // pixels, 320..4000
  int panel_height = 300;  // pixels of each panel's plot area, 120..4000
};

// Ticks covering [lo, hi]: `step` is 1, 2 or 5 x 10^k, chosen so that about `target` ticks
// span the range; lo/hi are rounded outwards to multiples of step. A single value (lo == hi)
// gets a range around it. Throws roiflow::Error when lo or hi is not finite or lo > hi.
struct Ticks {
  double lo = 0;
  double hi = 1;
  double step = 1;
  std::vector<double> values;  // lo, lo + step, ..., hi
};
Ticks nice_ticks(double lo, double hi, int target = 6);

// The SVG document; throws roiflow::Error as described above.
std::string plot_svg(const Plot& plot);
// plot_svg, written atomically to `path`.
void write_plot_svg(const std::string& path, const Plot& plot);

}  // namespace roiflow::report
