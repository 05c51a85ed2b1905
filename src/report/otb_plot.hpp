// OTB's success and precision plots for a benchmark: one curve per tracker, as tracking papers
// show them (Wu, Lim, Yang, "Object Tracking Benchmark", TPAMI 2015, Fig. 7).
//
//   using namespace roiflow;
//   std::vector<eval::BenchmarkRow> means = eval::tracker_means(rows, {"roiflow", "csrt"});
//   report::write_plot_svg("out/success.svg", report::success_plot(means));
//   report::write_plot_svg("out/precision.svg", report::precision_plot(means));
//
// The success plot draws, per tracker, the share of frames whose IoU exceeds each overlap
// threshold 0, 0.05, ..., 1; its legend gives each tracker's AUC in brackets, best first. The
// precision plot draws the share of frames whose centre error is within each threshold 0..50 px;
// its legend gives the value at 20 px, best first. Rows are usually tracker_means() (the curves
// averaged over the sequences); a single sequence's rows work too. Throws roiflow::Error when a
// row's curves do not have eval::kSuccessThresholds and eval::kPrecisionThresholds values, or
// when there is no row.
#pragma once

#include <string>
#include <vector>

#include "eval/otb_benchmark.hpp"
#include "report/plot.hpp"

namespace roiflow::report {

Plot success_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title = "");
Plot precision_plot(const std::vector<eval::BenchmarkRow>& rows, const std::string& title = "");

}  // namespace roiflow::report
