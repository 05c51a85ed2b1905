// roiflow sweep: error and time of dense LK as one parameter varies (pipeline::run_sweep).
#include <filesystem>
#include <iostream>

#include "cli_common.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {

void add_sweep_command(CLI::App& app, int& /*exit_code*/) {
  static LkOptions lk;
  static std::string dir, param = "all";
  static std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  static std::vector<double> values;
  static int max_pairs = 0;
  static bool progress = true;
  static pipeline::SweepRunOptions run;  // --out, --repeat
  CLI::App* sub = app.add_subcommand(
      "sweep", "Dense flow error and time as one LK parameter varies; CSV and SVG plots");
  add_pair_inputs(*sub, dir, pairs,
                  "Middlebury tree: DIR/<seq>/frame10.png, frame11.png, flow10.flo");
  sub->add_option("--param", param, "the parameter to vary (all: each in turn)")
      ->check(CLI::IsMember({"patch", "iterations", "levels", "sigma", "lambda", "all"}))
      ->capture_default_str();
  sub->add_option("--values", values,
                  "comma-separated values (default: patch 3..31, iterations 1..10, levels 1..6, "
                  "sigma 0..3, lambda 1e-8..1e-2)")
      ->type_name("LIST")
      ->delimiter(',')
      ->expected(1, 200);
  sub->add_option("--out", run.out_dir, "folder for sweep.csv and <param>.svg")->required();
  sub->add_option("--max-pairs", max_pairs, "use only the first N pairs (0 = all)")
      ->check(CLI::Range(0, 1000000));
  sub->add_option("--repeat", run.repeats, "runs of each pair per value, the fastest kept")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_flag("!--no-progress", progress, "no progress line per value on stderr");
  lk.threads = pipeline::default_threads();
  add_lk_options(*sub, lk);
  sub->callback([] {
    pipeline::SweepRunOptions o = run;
    o.base = lk_params(lk);
    o.plan = eval::sweep_plan(param, values, o.base);  // every value checked before any work
    o.pairs = eval::middlebury_or_listed(dir, pairs, max_pairs);
    const std::string name = std::filesystem::path(dir).lexically_normal().filename().string();
    o.subtitle = (dir.empty() ? "" : name + ", ") + "preset " + lk.preset;
    o.threads = lk.threads;
    if (progress) {
      o.progress = [](const eval::SweepRow& r, std::size_t i, std::size_t n) {
        std::cerr << eval::sweep_progress_line(r, i, n) << std::endl;
      };
    }
    std::cout << pipeline::sweep_text(pipeline::run_sweep(o), o);
  });
}

}  // namespace roiflow::cli
