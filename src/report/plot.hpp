// Line plots as standalone SVG files (any browser opens them), for sweeps and run-time figures.
//
//   using namespace roiflow::report;
//   Plot plot;
//   plot.title = "Error vs patch size";
//   plot.x_label = "patch size (px)";
//   PlotPanel& p = plot.panels.emplace_back();
//   p.y_label = "AAE (deg)";
//   p.y2_label = "EPE (px)";                      // a second y axis, on the right
//   p.series.push_back({"AAE", xs, aae});
//   p.series.push_back({"EPE", xs, epe, PlotAxis::Right});
//   write_plot_svg("out/patch.svg", plot);        // atomically
//
// Panels are stacked vertically and share the x axis (e.g. error above, run time below). Each
// axis gets "nice" ticks (1, 2 or 5 times a power of ten) that enclose its data; a log x axis
// gets one tick per decade. Points are joined by lines in the order given, with a marker at
// each (unless the series turns markers off). A point that cannot be drawn (NaN or infinite
// coordinate, or x <= 0 on a log axis) is skipped and its line is broken there: the gap shows,
// nothing is silently drawn at a wrong place. Inconsistent input throws roiflow::Error naming the
// plot and the series: x and y of different lengths, no panel, a panel with no drawable point.
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
