// Whole runs of the evaluation commands on the caller's thread count. run_eval: dense flow of
// every pair scored against its ground truth (eval::evaluate_pair), optionally with the HTML
// report. run_sweep: a whole `roiflow sweep`: eval::sweep for each parameter in turn on the
// caller's threads, sweep.csv rewritten after each parameter (an interrupted run keeps what is
// complete) and one SVG plot per parameter, in an output folder that is created when missing (its
// parent must exist: a mistyped path fails before minutes of computation).
//
//   const auto pairs = roiflow::eval::find_middlebury("data/middlebury");
//   const auto rows = roiflow::pipeline::run_eval(pairs, roiflow::flow::LkParams::paper(), 2);
//   std::cout << roiflow::eval::format_table(rows);
//
//   roiflow::pipeline::SweepRunOptions o;
//   o.pairs = roiflow::eval::find_middlebury("data/middlebury");
//   o.plan = roiflow::eval::sweep_plan("patch", {}, o.base);
//   o.out_dir = "out/sweep";
//   const roiflow::pipeline::SweepRunResult r = roiflow::pipeline::run_sweep(o);
//   std::cout << roiflow::eval::sweep_table(r.rows);
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "eval/flow_input.hpp"
#include "eval/sweep.hpp"
#include "report/html_report.hpp"

namespace roiflow::pipeline {

// Dense flow of one input pair on `threads` threads, timed (dense_flow alone), and its error
// when the input has a ground truth.
struct FlowRun {
  cv::Mat flow;  // CV_32FC2
  double ms = 0;
  std::optional<flow::FlowErrors> errors;
};
FlowRun run_flow(const eval::FlowInput& in, const flow::LkParams& params, int threads);

// With `report`, each pair's images and row are added to it.
std::vector<eval::EvalRow> run_eval(const std::vector<eval::EvalPair>& pairs,
                                    const flow::LkParams& params, int threads,
                                    report::HtmlReport* report = nullptr);

struct SweepRunOptions {
  std::vector<eval::EvalPair> pairs;
  flow::LkParams base = flow::LkParams::paper();
  std::vector<std::pair<eval::SweepParam, std::vector<double>>> plan;  // eval::sweep_plan
  std::string out_dir;
  std::string subtitle;  // of the plots
  int threads = 1;
  int repeats = 3;
  // After each value: its parameter, its row, its index and the count of values.
  std::function<void(const eval::SweepRow&, std::size_t index, std::size_t count)> progress;
};

struct SweepRunResult {
  std::vector<eval::SweepRow> rows;
  std::vector<std::string> written;  // sweep.csv, then one SVG per parameter
};

// Throws roiflow::Error for an out_dir that cannot be made, and what eval::sweep throws.
SweepRunResult run_sweep(const SweepRunOptions& options);

}  // namespace roiflow::pipeline
