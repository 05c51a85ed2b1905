// OTB's success and precision plots for a benchmark, one curve per tracker as tracking papers
// show them (Wu, Lim, Yang, TPAMI 2015, Fig. 7), with each tracker's AUC or precision@20 in its
// legend, best first (docs/REPORTS.md). Rows are usually eval::tracker_means.
//
//   const std::vector<roiflow::eval::BenchmarkRow> rows;  // from eval::score_run
//   if (rows.empty()) return;
//   const auto means = roiflow::eval::tracker_means(rows, {"roiflow", "csrt"});
//   roiflow::report::write_plot_svg("out/success.svg", roiflow::report::success_plot(means));
//   roiflow::report::write_plot_svg("out/precision.svg", roiflow::report::precision_plot(means));
#pragma once

#include <string>
#include <vector>

#include "eval/otb_benchmark.hpp"
#include "report/plot.hpp"

namespace roiflow::report {

Plot success_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title = "");
Plot precision_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title = "");

}  // namespace roiflow::report
