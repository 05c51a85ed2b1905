// roiflow sweep: error and run time of dense LK as one parameter varies (paper Fig. 7, 8).
//
//   roiflow sweep data/middlebury --param patch --out out/sweep
//   -> out/sweep/sweep.csv, out/sweep/patch.svg
#include <filesystem>
#include <iostream>

#include "cli_common.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

struct SweepCommand {
  LkOptions lk;
  std::string dir;
  std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  std::string param = "all";
  std::vector<double> values;
  int max_pairs = 0;
  bool progress = true;
  pipeline::SweepRunOptions run;  // --out, --repeat
};

void run_sweep(const SweepCommand& cmd) {
  pipeline::SweepRunOptions o = cmd.run;
  o.base = lk_params(cmd.lk);
  // Every value is checked before the first pair is read.
  o.plan = eval::sweep_plan(cmd.param, cmd.values, o.base);
  o.pairs = eval::middlebury_or_listed(cmd.dir, cmd.pairs, cmd.max_pairs);
  o.subtitle =
      (cmd.dir.empty() ? "" : fs::path(cmd.dir).lexically_normal().filename().string() + ", ") +
      "preset " + cmd.lk.preset;
  o.threads = cmd.lk.threads;
  if (cmd.progress) {
    o.progress = [](const eval::SweepRow& r, std::size_t i, std::size_t n) {
      std::cerr << eval::sweep_progress_line(r, i, n) << std::endl;
    };
  }
  const pipeline::SweepRunResult r = pipeline::run_sweep(o);
  std::cout << eval::sweep_table(r.rows) << "swept " << r.rows.size() << " values over "
            << o.pairs.size() << " pairs, " << cmd.lk.threads
            << " threads, time per pair the fastest of " << o.repeats
            << (o.repeats == 1 ? " run" : " runs") << "; wrote " << joined(r.written) << "\n";
}

}  // namespace

void add_sweep_command(CLI::App& app, int& /*exit_code*/) {
  static SweepCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "sweep", "Dense flow error and time as one LK parameter varies; CSV and SVG plots");
  CLI::Option* dir =
      sub->add_option("DIR", cmd.dir,
                      "Middlebury tree: DIR/<seq>/frame10.png, frame11.png, flow10.flo")
          ->type_name("DIR");
  CLI::Option* pair = sub->add_option("--pair", cmd.pairs, "an image pair and its .flo; repeatable")
                          ->type_name("A B GT")
                          ->type_size(3)
                          ->allow_extra_args(false);
  dir->excludes(pair);
  sub->add_option("--param", cmd.param, "the parameter to vary (all: each in turn)")
      ->type_name("NAME")
      ->check(CLI::IsMember({"patch", "iterations", "levels", "sigma", "lambda", "all"}))
      ->capture_default_str();
  sub->add_option("--values", cmd.values,
                  "comma-separated values (default: patch 3..31, iterations 1..10, levels 1..6, "
                  "sigma 0..3, lambda 1e-8..1e-2)")
      ->type_name("LIST")
      ->delimiter(',')
      ->expected(1, 200);
  sub->add_option("--out", cmd.run.out_dir,
                  "folder for sweep.csv and <param>.svg (created if missing)")
      ->type_name("DIR")
      ->required();
  sub->add_option("--max-pairs", cmd.max_pairs, "use only the first N pairs (0 = all)")
      ->check(CLI::Range(0, 1000000));
  sub->add_option(
         "--repeat", cmd.run.repeats,
         "runs of each pair per value; its time is the fastest (noise of a shared machine)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_flag("!--no-progress", cmd.progress, "no progress line per value on stderr");
  cmd.lk.threads = pipeline::default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([] { run_sweep(cmd); });
}

}  // namespace roiflow::cli
