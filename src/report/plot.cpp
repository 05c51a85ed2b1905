#include "report/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::report {
namespace {

constexpr const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c",
                                   "#ff7f0e", "#9467bd", "#8c564b"};
constexpr int kColorCount = sizeof kColors / sizeof kColors[0];

// Approximate advance of a 12 px sans-serif glyph, for laying out the legend.
constexpr double kCharWidth = 7.0;

std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f", v);
  return buffer;
}

// The 1, 2 or 5 x 10^k closest to x.
double nice_number(double x) {
  const double exponent = std::floor(std::log10(x));
  const double fraction = x / std::pow(10.0, exponent);
  const double nice = fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10;
  return nice * std::pow(10.0, exponent);
}

// Tick labels with as many decimals as the step needs, so 0.25-steps read 0.25, not 0.2.
std::string tick_label(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0;
  char buffer[32];
  if (std::abs(v) >= 1e6 || step < 1e-4) {
    std::snprintf(buffer, sizeof buffer, "%g", v);
  } else {
    const int decimals =
        step >= 1 ? 0 : std::min(10, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  }
  return buffer;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
};

// One axis: where values go, and the ticks to draw.
struct Axis {
  bool log = false;
  double lo = 0, hi = 1;  // in axis units (log10 of the value on a log axis)
  std::vector<double> ticks;
  std::vector<std::string> labels;

  double fraction(double v) const {
    const double a = log ? std::log10(v) : v;
    return (a - lo) / (hi - lo);
  }
};

Axis linear_axis(const Range& r) {
  const Ticks t = nice_ticks(r.lo, r.hi);
  Axis axis;
  axis.lo = t.lo;
  axis.hi = t.hi;
  for (double v : t.values) {
    axis.ticks.push_back(v);
    axis.labels.push_back(tick_label(v, t.step));
  }
  return axis;
}

Axis log_axis(const Range& r) {
  Axis axis;
  axis.log = true;
  axis.lo = std::floor(std::log10(r.lo) + 1e-9);
  axis.hi = std::ceil(std::log10(r.hi) - 1e-9);
  if (axis.hi <= axis.lo) axis.hi = axis.lo + 1;
  for (double e = axis.lo; e <= axis.hi + 0.5; e += 1) {
    axis.ticks.push_back(std::pow(10.0, e));
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", std::pow(10.0, e));
    axis.labels.push_back(buffer);
  }
  return axis;
}

bool plottable(double x, double y, bool x_log) {
  return std::isfinite(x) && std::isfinite(y) && (!x_log || x > 0);
}

void check_plot(const Plot& plot) {
  const std::string name = "plot '" + plot.title + "'";
  if (plot.panels.empty()) throw Error(name + " has no panel");
  if (plot.width < 320 || plot.width > 4000) {
    throw Error(name + ": width must be in 320..4000, got " + std::to_string(plot.width));
  }
  if (plot.panel_height < 120 || plot.panel_height > 4000) {
    throw Error(name + ": panel height must be in 120..4000, got " +
                std::to_string(plot.panel_height));
  }
  for (std::size_t p = 0; p < plot.panels.size(); ++p) {
    const PlotPanel& panel = plot.panels[p];
    const std::string where = name + " panel " + std::to_string(p + 1);
    bool any = false;
    for (const PlotSeries& s : panel.series) {
      if (s.x.size() != s.y.size()) {
        throw Error(where + ": series '" + s.name + "' has " + std::to_string(s.x.size()) +
                    " x values but " + std::to_string(s.y.size()) + " y values");
      }
      if (s.axis == PlotAxis::Right && panel.y2_label.empty()) {
        throw Error(where + ": series '" + s.name + "' is on the right axis, which has no label");
      }
      for (std::size_t i = 0; i < s.x.size(); ++i)
        any = any || plottable(s.x[i], s.y[i], plot.x_log);
    }
    if (!any) throw Error(where + " ('" + panel.y_label + "') has no point to draw");
  }
}

}  // namespace

Ticks nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi) {
    throw Error("ticks need a finite range lo <= hi, got [" + number_text(lo) + ", " +
                number_text(hi) + "]");
  }
  target = std::max(target, 2);
  if (lo == hi) {
    const double delta = lo == 0 ? 1.0 : std::abs(lo) * 0.1;
    if (lo != 0) lo -= delta;  // an all-zero series sits on the axis: [0, 1]
    hi += delta;
  }
  Ticks t;
  t.step = nice_number((hi - lo) / (target - 1));
  t.lo = std::floor(lo / t.step + 1e-9) * t.step;
  t.hi = std::ceil(hi / t.step - 1e-9) * t.step;
  const long long n = std::llround((t.hi - t.lo) / t.step);
  for (long long i = 0; i <= n; ++i)
    t.values.push_back(t.lo + static_cast<double>(i) * t.step);
  return t;
}

namespace {

// The legend of `panel`: rows of items wrapped between `left` and `right`, the first row's
// baseline at `ly`, which is left at the last row's.
std::string legend_svg(const PlotPanel& panel, double left, double right, double& ly) {
  std::string body;
  double lx = left;
  for (std::size_t i = 0; i < panel.series.size(); ++i) {
    const PlotSeries& s = panel.series[i];
    const double item_w = 34 + kCharWidth * static_cast<double>(s.name.size()) + 18;
    if (lx > left && lx + item_w > right) {
      lx = left;
      ly += 18;
    }
    const char* color = kColors[i % kColorCount];
    const std::string dash =
        s.axis == PlotAxis::Right ? " stroke-dasharray=\"6 3\"" : std::string();
    body += "<g class=\"legend\"><line x1=\"" + num(lx) + "\" y1=\"" + num(ly - 4) + "\" x2=\"" +
            num(lx + 24) + "\" y2=\"" + num(ly - 4) + "\" stroke=\"" + color +
            "\" stroke-width=\"2\"" + dash + "/><circle cx=\"" + num(lx + 12) + "\" cy=\"" +
            num(ly - 4) + "\" r=\"3\" fill=\"" + color + "\"/><text x=\"" + num(lx + 30) +
            "\" y=\"" + num(ly) + "\" font-size=\"12\">" + escape_markup(s.name) + "</text></g>\n";
    lx += item_w;
  }
  return body;
}

// The series of `panel`: polylines broken at undrawable points, then the markers on top. `px`
// maps x to pixels, `py(axis, y)` y on the left (0) or right (1) axis.
std::string series_svg(const PlotPanel& panel, bool x_log, const std::function<double(double)>& px,
                       const std::function<double(int, double)>& py) {
  std::string body;
  for (std::size_t i = 0; i < panel.series.size(); ++i) {
    const PlotSeries& s = panel.series[i];
    const int axis = s.axis == PlotAxis::Right ? 1 : 0;
    const char* color = kColors[i % kColorCount];
    std::string d;
    std::string markers;
    bool pen_down = false;
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!plottable(s.x[k], s.y[k], x_log)) {
        pen_down = false;
        continue;
      }
      const double cx = px(s.x[k]);
      const double cy = py(axis, s.y[k]);
      d += (pen_down ? " L" : (d.empty() ? "M" : " M")) + num(cx) + " " + num(cy);
      pen_down = true;
      if (s.markers) {
        markers += "<circle class=\"marker\" cx=\"" + num(cx) + "\" cy=\"" + num(cy) +
                   "\" r=\"3\" fill=\"" + color + "\"/>\n";
      }
    }
    body += "<g class=\"series\">\n";
    if (!d.empty()) {
      body += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + color + "\" stroke-width=\"1.8\"" +
              (s.axis == PlotAxis::Right ? " stroke-dasharray=\"6 3\"" : "") + "/>\n";
    }
    body += markers + "</g>\n";
  }
  return body;
}

}  // namespace

std::string plot_svg(const Plot& plot) {
  check_plot(plot);

  bool any_right = false;
  Range x_range;
  for (const PlotPanel& panel : plot.panels) {
    any_right = any_right || !panel.y2_label.empty();
    for (const PlotSeries& s : panel.series) {
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (plottable(s.x[i], s.y[i], plot.x_log)) x_range.add(s.x[i]);
      }
    }
  }
  const Axis x_axis = plot.x_log ? log_axis(x_range) : linear_axis(x_range);

  const double left = 80;
  const double right = plot.width - (any_right ? 80.0 : 24.0);
  const double area_w = right - left;
  const auto px = [&](double x) { return left + x_axis.fraction(x) * area_w; };

  std::string body;
  double y = 14;
  if (!plot.title.empty()) {
    body += "<text class=\"title\" x=\"" + num(plot.width / 2.0) + "\" y=\"" + num(y + 14) +
            "\" text-anchor=\"middle\" font-size=\"16\" font-weight=\"bold\">" +
            escape_markup(plot.title) + "</text>\n";
    y += 26;
  }

  for (std::size_t p = 0; p < plot.panels.size(); ++p) {
    const PlotPanel& panel = plot.panels[p];
    const bool last = p + 1 == plot.panels.size();

    // Legend rows, wrapped at the plot's width.
    double ly = y + 12;
    body += legend_svg(panel, left, right, ly);
    const double top = ly + 12;
    const double bottom = top + plot.panel_height;

    Range ranges[2];
    for (const PlotSeries& s : panel.series) {
      Range& r = ranges[s.axis == PlotAxis::Right ? 1 : 0];
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (plottable(s.x[i], s.y[i], plot.x_log)) r.add(s.y[i]);
      }
    }
    Axis y_axes[2];
    for (int a = 0; a < 2; ++a) {
      if (ranges[a].empty()) continue;
      if (panel.y_from_zero) ranges[a].add(0.0);
      y_axes[a] = linear_axis(ranges[a]);
    }
    const bool has_left = !ranges[0].empty();
    const bool has_right = !ranges[1].empty();
    const auto py = [&](const Axis& axis, double v) {
      return bottom - axis.fraction(v) * plot.panel_height;
    };

    // Grid and ticks. The grid follows the left axis (or the right one when alone).
    const Axis& grid_axis = has_left ? y_axes[0] : y_axes[1];
    for (std::size_t i = 0; i < grid_axis.ticks.size(); ++i) {
      const double ty = py(grid_axis, grid_axis.ticks[i]);
      body += "<line class=\"grid\" x1=\"" + num(left) + "\" y1=\"" + num(ty) + "\" x2=\"" +
              num(right) + "\" y2=\"" + num(ty) + "\" stroke=\"#e0e0e0\"/>\n";
    }
    for (std::size_t i = 0; i < x_axis.ticks.size(); ++i) {
      const double tx = px(x_axis.ticks[i]);
      body += "<line class=\"grid\" x1=\"" + num(tx) + "\" y1=\"" + num(top) + "\" x2=\"" +
              num(tx) + "\" y2=\"" + num(bottom) + "\" stroke=\"#e0e0e0\"/>\n";
      body += "<text class=\"xtick\" x=\"" + num(tx) + "\" y=\"" + num(bottom + 16) +
              "\" text-anchor=\"middle\" font-size=\"11\">" + escape_markup(x_axis.labels[i]) +
              "</text>\n";
    }
    for (int a = 0; a < 2; ++a) {
      if (a == 0 ? !has_left : !has_right) continue;
      const Axis& axis = y_axes[a];
      for (std::size_t i = 0; i < axis.ticks.size(); ++i) {
        const double ty = py(axis, axis.ticks[i]);
        const double tx = a == 0 ? left - 6 : right + 6;
        body += "<text class=\"ytick\" x=\"" + num(tx) + "\" y=\"" + num(ty + 4) +
                "\" text-anchor=\"" + (a == 0 ? "end" : "start") + "\" font-size=\"11\">" +
                escape_markup(axis.labels[i]) + "</text>\n";
      }
    }
    body += "<rect class=\"plot-area\" x=\"" + num(left) + "\" y=\"" + num(top) + "\" width=\"" +
            num(area_w) + "\" height=\"" + num(plot.panel_height) +
            "\" fill=\"none\" stroke=\"#444\"/>\n";
    const double mid = (top + bottom) / 2;
    body += "<text class=\"ylabel\" x=\"20\" y=\"" + num(mid) +
            "\" text-anchor=\"middle\" font-size=\"13\" transform=\"rotate(-90 20 " + num(mid) +
            ")\">" + escape_markup(panel.y_label) + "</text>\n";
    if (!panel.y2_label.empty()) {
      const double x2 = plot.width - 14.0;
      body += "<text class=\"ylabel\" x=\"" + num(x2) + "\" y=\"" + num(mid) +
              "\" text-anchor=\"middle\" font-size=\"13\" transform=\"rotate(90 " + num(x2) + " " +
              num(mid) + ")\">" + escape_markup(panel.y2_label) + "</text>\n";
    }

    body += series_svg(panel, plot.x_log, px, [&](int a, double v) { return py(y_axes[a], v); });
    y = bottom + 24;
    if (last) {
      body += "<text class=\"xlabel\" x=\"" + num((left + right) / 2) + "\" y=\"" + num(y + 12) +
              "\" text-anchor=\"middle\" font-size=\"13\">" + escape_markup(plot.x_label) +
              "</text>\n";
      y += 24;
    }
  }

  const std::string height = num(y);
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
         std::to_string(plot.width) + "\" height=\"" + height + "\" viewBox=\"0 0 " +
         std::to_string(plot.width) + " " + height +
         "\" font-family=\"DejaVu Sans, Arial, Helvetica, sans-serif\">\n"
         "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n" +
         body + "</svg>\n";
}

void write_plot_svg(const std::string& path, const Plot& plot) {
  write_text_atomically(path, plot_svg(plot));
}

}  // namespace roiflow::report
