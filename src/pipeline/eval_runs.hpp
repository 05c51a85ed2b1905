// Whole runs of the evaluation commands on a given thread count: run_flow (one pair, timed, and
// its error), run_eval (every pair scored against its ground truth, optionally into the HTML
// report) and run_sweep (`roiflow sweep`: eval::sweep for each parameter in turn, sweep.csv
// rewritten after each, so an interrupted run keeps what is complete, and one SVG plot per
// parameter, in an output folder created when missing; its parent must exist).
//
//   const auto pairs = roiflow::eval::find_middlebury("data/middlebury");
//   const auto rows = roiflow::pipeline::run_eval(pairs, roiflow::flow::LkParams::paper(), 2);
//   std::cout << roiflow::eval::format_table(rows);
//   roiflow::pipeline::SweepRunOptions o;
//   o.pairs = pairs;
//   o.plan = roiflow::eval::sweep_plan("patch", {}, o.base);
//   o.out_dir = "out/sweep";
//   std::cout << roiflow::eval::sweep_table(roiflow::pipeline::run_sweep(o).rows);
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

// `roiflow flow`'s files: the flow as Middlebury .flo and, when named, its colour coding
// (saturated at the truth's largest vector when the input has one, else at the 99th percentile
// of its magnitudes) and the colour-wheel legend. check() throws roiflow::Error for a path that
// cannot be written, before any work.
struct FlowFiles {
  std::string flo, color, legend;
  void check() const;
};
// Writes the files and returns their paths; throws roiflow::Error, writing nothing, when the
// run was scored against a ground truth that is unknown at every pixel.
std::vector<std::string> write_flow_files(const FlowFiles& files, const eval::FlowInput& in,
                                          const FlowRun& run);
// "flow 640x480 (SOURCE): 12.34 ms, wrote FILES", and the error line when the run was scored.
std::string flow_text(const eval::FlowInput& in, const FlowRun& run,
                      const std::vector<std::string>& written);

// With `report`, each pair's images and row are added to it.
std::vector<eval::EvalRow> run_eval(const std::vector<eval::EvalPair>& pairs,
                                    const flow::LkParams& params, int threads,
                                    report::HtmlReport* report = nullptr);

// `roiflow eval`'s outputs: the rows as `format` (table, csv or json) to `output` (empty: into
// the returned text) and, with `report`, the HTML report titled `title`. check() throws
// roiflow::Error for a path that cannot be written, before any work.
struct EvalOutputs {
  std::string format = "table";
  std::string output;
  std::string report;
  std::string title;
  void check() const;
};
// Scores every pair, writes the outputs; returns what the command prints (the rows when
// `output` is empty, then one line per file written).
std::string run_eval(const std::vector<eval::EvalPair>& pairs, const flow::LkParams& params,
                     const std::string& preset, int threads, const EvalOutputs& outputs);

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
// What `roiflow sweep` prints: the table, then "swept V values over P pairs, T threads, time per
// pair the fastest of R runs; wrote FILES".
std::string sweep_text(const SweepRunResult& result, const SweepRunOptions& options);

}  // namespace roiflow::pipeline
