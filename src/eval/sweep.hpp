// Parameter sweeps of dense LK over pairs with ground truth (the paper's Fig. 7 and 8): one
// parameter varies, the others keep the base values; each value is evaluated on every pair
// (evaluate_pair, dense LK timed alone, the fastest of `repeats` runs) and summarised as mean
// AAE, mean EPE and mean milliseconds per pair. A value the parameter cannot take throws
// roiflow::Error naming it.
//
//   const auto pairs = roiflow::eval::find_middlebury("data/middlebury");
//   const auto plan = roiflow::eval::sweep_plan("patch", {5, 9, 13}, roiflow::flow::LkParams{});
//   const auto rows = roiflow::eval::sweep(pairs, roiflow::flow::LkParams::paper(),
//                                          plan[0].first, plan[0].second);
//   std::cout << roiflow::eval::sweep_table(rows) << roiflow::eval::sweep_csv(rows);
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/executor.hpp"
#include "eval/flow_eval.hpp"
#include "flow/dense_lk.hpp"

namespace roiflow::eval {

enum class SweepParam { Patch, Iterations, Levels, Sigma, Lambda };

const char* to_string(SweepParam param);  // "patch", "iterations", "levels", "sigma", "lambda"
// Throws roiflow::Error naming an unknown name.
SweepParam sweep_param_from_string(std::string_view name);
std::vector<SweepParam> all_sweep_params();  // in the order above

// patch 3..31 (every size), iterations 1..10, levels 1..6; sigma 0..3 px and lambda
// 1e-8..1e-2 (decades), each with the base value added when it is not in the list.
std::vector<double> default_sweep_values(SweepParam param, const flow::LkParams& base);

// The parameters `name` stands for ("all": every one) and each one's values: `values`, or its
// default_sweep_values when empty, each checked with with_value. Throws UsageError ("--values:
// ...") for a value a parameter cannot take, and for values given with "all".
std::vector<std::pair<SweepParam, std::vector<double>>> sweep_plan(
    const std::string& name, const std::vector<double>& values, const flow::LkParams& base);

// `base` with `param` set to `value`; throws roiflow::Error ("patch 40: patch must be in
// 3..31, got 40") when the result is invalid or an integer parameter gets a fraction.
flow::LkParams with_value(const flow::LkParams& base, SweepParam param, double value);

struct SweepRow {
  SweepParam param = SweepParam::Patch;
  double value = 0;
  double aae_deg = 0;      // mean over the pairs
  double epe = 0;          // mean over the pairs, pixels
  double ms_per_pair = 0;  // mean over the pairs of dense_flow's time, milliseconds
  int pairs = 0;
};

// Called after each value, with its 0-based index among `values`.
using SweepProgress = std::function<void(const SweepRow& row, std::size_t index)>;

// All values are checked (with_value) before any is evaluated. One untimed warm-up run of the
// first pair precedes the sweep, so the first value's time holds no one-off start-up cost.
// Each pair is run `repeats` times (1..100) and its time is the fastest run: on a shared machine
// the minimum is what the computation costs, the rest is other processes' interference.
// Throws roiflow::Error when `pairs` or `values` is empty or `repeats` is out of range, and what
// evaluate_pair throws.
std::vector<SweepRow> sweep(const std::vector<EvalPair>& pairs, const flow::LkParams& base,
                            SweepParam param, const std::vector<double>& values,
                            const Executor* executor = nullptr, const SweepProgress& progress = {},
                            int repeats = 1);

// A value as the CSV and progress lines show it: integers without decimals, others "%g".
std::string sweep_value_text(double value);
// Header `parameter,value,aae_deg,epe,ms_per_pair`; aae 3 decimals, epe 4, ms 2.
std::string sweep_csv(const std::vector<SweepRow>& rows);
// "sweep patch 7 (3/29): AAE 4.123 deg, EPE 0.4123 px, 12.34 ms/pair" for value i of n.
std::string sweep_progress_line(const SweepRow& row, std::size_t index, std::size_t count);
// The table `roiflow sweep` prints: parameter, value, AAE, EPE, ms per pair.
std::string sweep_table(const std::vector<SweepRow>& rows);

}  // namespace roiflow::eval
