// A whole `roiflow sweep` run: eval::sweep for each parameter in turn on the caller's threads,
// sweep.csv rewritten after each parameter (an interrupted run keeps what is complete) and one
// SVG plot per parameter, in an output folder that is created when missing (its parent must
// exist: a mistyped path fails before minutes of computation).
//
//   roiflow::pipeline::SweepRunOptions o;
//   o.pairs = roiflow::eval::find_middlebury("data/middlebury");
//   o.params = {roiflow::eval::SweepParam::Patch};
//   o.values = {roiflow::eval::default_sweep_values(o.params[0], o.base)};
//   o.out_dir = "out/sweep";
//   const roiflow::pipeline::SweepRunResult r = roiflow::pipeline::run_sweep(o);
//   std::cout << roiflow::eval::sweep_table(r.rows);
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "eval/sweep.hpp"

namespace roiflow::pipeline {

struct SweepRunOptions {
  std::vector<eval::EvalPair> pairs;
  flow::LkParams base = flow::LkParams::paper();
  std::vector<eval::SweepParam> params;
  std::vector<std::vector<double>> values;  // one list per parameter
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
