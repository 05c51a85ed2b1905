#include "report/otb_plot.hpp"

#include <algorithm>
#include <cstdio>

#include "core/error.hpp"

namespace roiflow::report {
namespace {

std::string three(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", v);
  return text;
}

void check(const std::vector<eval::BenchmarkRow>& rows) {
  if (rows.empty()) throw Error("OTB plot: no tracker to draw");
  for (const eval::BenchmarkRow& r : rows) {
    if (r.curves.success.size() != static_cast<std::size_t>(eval::kSuccessThresholds) ||
        r.curves.precision.size() != static_cast<std::size_t>(eval::kPrecisionThresholds)) {
      throw Error("OTB plot: " + r.tracker + " on " + r.sequence + " has " +
                  std::to_string(r.curves.success.size()) + " success and " +
                  std::to_string(r.curves.precision.size()) + " precision values, expected " +
                  std::to_string(eval::kSuccessThresholds) + " and " +
                  std::to_string(eval::kPrecisionThresholds));
    }
  }
}

// Rows ordered by `key`, best first (ties keep the given order).
template <class Key>
std::vector<const eval::BenchmarkRow*> best_first(const std::vector<eval::BenchmarkRow>& rows,
                                                  Key key) {
  std::vector<const eval::BenchmarkRow*> order;
  for (const eval::BenchmarkRow& r : rows)
    order.push_back(&r);
  std::stable_sort(order.begin(), order.end(),
                   [&](const auto* a, const auto* b) { return key(*a) > key(*b); });
  return order;
}

std::string sequences_text(const std::vector<eval::BenchmarkRow>& rows) {
  const int n = rows.front().sequences;
  if (rows.front().sequence != "mean") return rows.front().sequence;
  return std::to_string(n) + (n == 1 ? " sequence" : " sequences");
}

}  // namespace

Plot success_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title) {
  check(rows);
  Plot plot;
  plot.title = title.empty() ? "Success plots of OPE (" + sequences_text(rows) + ")" : title;
  plot.x_label = "overlap threshold (IoU)";
  PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "success rate";
  panel.y_from_zero = true;
  std::vector<double> x;
  for (int k = 0; k < eval::kSuccessThresholds; ++k)
    x.push_back(static_cast<double>(k) / (eval::kSuccessThresholds - 1));
  for (const eval::BenchmarkRow* r :
       best_first(rows, [](const eval::BenchmarkRow& row) { return row.auc; })) {
    panel.series.push_back({r->tracker + " [" + three(r->auc) + "]", x, r->curves.success});
  }
  return plot;
}

Plot precision_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title) {
  check(rows);
  Plot plot;
  plot.title = title.empty() ? "Precision plots of OPE (" + sequences_text(rows) + ")" : title;
  plot.x_label = "location error threshold (px)";
  PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "precision";
  panel.y_from_zero = true;
  std::vector<double> x;
  for (int k = 0; k < eval::kPrecisionThresholds; ++k)
    x.push_back(k);
  for (const eval::BenchmarkRow* r :
       best_first(rows, [](const eval::BenchmarkRow& row) { return row.precision20; })) {
    PlotSeries s{r->tracker + " [" + three(r->precision20) + "]", x, r->curves.precision};
    s.markers = false;
    panel.series.push_back(s);
  }
  return plot;
}

}  // namespace roiflow::report
