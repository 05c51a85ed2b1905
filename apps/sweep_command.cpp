// roiflow sweep: error and run time of dense LK as one parameter varies (paper Fig. 7, 8).
//
//   roiflow sweep data/middlebury --param patch --out out/sweep
//   -> out/sweep/sweep.csv, out/sweep/patch.svg
#include <filesystem>
#include <iostream>

#include "cli_common.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/sweep_run.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

struct SweepCommand {
  LkOptions lk;
  std::string dir;
  std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  std::string param = "all";
  std::vector<double> values;
  std::string out;
  int max_pairs = 0;
  int repeats = 3;
  bool progress = true;
};

std::vector<eval::EvalPair> sweep_pairs(const SweepCommand& cmd) {
  if (cmd.dir.empty() && cmd.pairs.empty()) {
    throw UsageError("sweep needs a Middlebury directory DIR or at least one --pair A B GT");
  }
  std::vector<eval::EvalPair> pairs =
      cmd.dir.empty() ? eval::listed_pairs(cmd.pairs) : eval::find_middlebury(cmd.dir);
  if (cmd.max_pairs > 0 && pairs.size() > static_cast<std::size_t>(cmd.max_pairs)) {
    pairs.resize(static_cast<std::size_t>(cmd.max_pairs));
  }
  return pairs;
}

void run_sweep(const SweepCommand& cmd) {
  pipeline::SweepRunOptions o;
  o.base = lk_params(cmd.lk);
  if (cmd.param == "all") {
    if (!cmd.values.empty()) throw UsageError("--values needs one --param, not all");
    o.params = eval::all_sweep_params();
  } else {
    o.params.push_back(eval::sweep_param_from_string(cmd.param));
  }
  // Every value is checked before the first pair is read.
  for (eval::SweepParam p : o.params) {
    o.values.push_back(cmd.values.empty() ? eval::default_sweep_values(p, o.base) : cmd.values);
    for (double v : o.values.back()) {
      try {
        eval::with_value(o.base, p, v);
      } catch (const Error& e) {
        throw UsageError(std::string("--values: ") + e.what());
      }
    }
  }
  o.pairs = sweep_pairs(cmd);
  o.out_dir = cmd.out;
  o.subtitle =
      (cmd.dir.empty() ? "" : fs::path(cmd.dir).lexically_normal().filename().string() + ", ") +
      "preset " + cmd.lk.preset;
  o.threads = cmd.lk.threads;
  o.repeats = cmd.repeats;
  if (cmd.progress) {
    o.progress = [](const eval::SweepRow& r, std::size_t i, std::size_t n) {
      std::cerr << "sweep " << eval::to_string(r.param) << " " << eval::sweep_value_text(r.value)
                << " (" << i + 1 << "/" << n << "): AAE " << fixed(r.aae_deg, 3) << " deg, EPE "
                << fixed(r.epe, 4) << " px, " << fixed(r.ms_per_pair, 2) << " ms/pair" << std::endl;
    };
  }
  const pipeline::SweepRunResult r = pipeline::run_sweep(o);
  std::cout << eval::sweep_table(r.rows) << "swept " << r.rows.size() << " values over "
            << o.pairs.size() << " pairs, " << cmd.lk.threads
            << " threads, time per pair the fastest of " << cmd.repeats
            << (cmd.repeats == 1 ? " run" : " runs") << "; wrote " << joined(r.written) << "\n";
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
  sub->add_option("--out", cmd.out, "folder for sweep.csv and <param>.svg (created if missing)")
      ->type_name("DIR")
      ->required();
  sub->add_option("--max-pairs", cmd.max_pairs, "use only the first N pairs (0 = all)")
      ->check(CLI::Range(0, 1000000));
  sub->add_option(
         "--repeat", cmd.repeats,
         "runs of each pair per value; its time is the fastest (noise of a shared machine)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_flag("!--no-progress", cmd.progress, "no progress line per value on stderr");
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([] { run_sweep(cmd); });
}

}  // namespace roiflow::cli
