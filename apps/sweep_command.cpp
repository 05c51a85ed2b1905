// roiflow sweep: error and run time of dense LK as one parameter varies (paper Fig. 7, 8).
//
//   roiflow sweep data/middlebury --param patch --out out/sweep
//   -> out/sweep/sweep.csv, out/sweep/patch.svg
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "eval/flow_eval.hpp"
#include "eval/sweep.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/sweep_plot.hpp"

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
  std::vector<eval::EvalPair> pairs;
  if (!cmd.dir.empty()) {
    pairs = eval::find_middlebury(cmd.dir);
  } else {
    for (std::size_t i = 0; i < cmd.pairs.size(); ++i) {
      const std::vector<std::string>& p = cmd.pairs[i];
      eval::EvalPair pair;
      pair.name = "pair" + std::to_string(i + 1);
      pair.frame0 = p.at(0);
      pair.frame1 = p.at(1);
      pair.ground_truth = p.at(2);
      pairs.push_back(pair);
    }
  }
  if (cmd.max_pairs > 0 && pairs.size() > static_cast<std::size_t>(cmd.max_pairs)) {
    pairs.resize(static_cast<std::size_t>(cmd.max_pairs));
  }
  return pairs;
}

// The output folder is created when missing, but its parent must exist: a mistyped path fails
// before minutes of computation instead of growing a tree somewhere unexpected.
void prepare_out_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  if (fs::exists(dir, ec)) throw Error("--out: '" + dir + "' exists and is not a directory");
  const fs::path parent = fs::path(dir).lexically_normal().parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error("--out: directory '" + parent.string() + "' of '" + dir + "' does not exist");
  }
  if (!fs::create_directory(dir, ec) && !fs::is_directory(dir)) {
    throw Error("--out: cannot create directory '" + dir + "': " + ec.message());
  }
}

std::string subtitle(const SweepCommand& cmd) {
  if (cmd.dir.empty()) return "preset " + cmd.lk.preset;
  return fs::path(cmd.dir).lexically_normal().filename().string() + ", preset " + cmd.lk.preset;
}

void run_sweep(const SweepCommand& cmd) {
  const flow::LkParams base = lk_params(cmd.lk);
  std::vector<eval::SweepParam> params;
  if (cmd.param == "all") {
    if (!cmd.values.empty()) throw UsageError("--values needs one --param, not all");
    params = eval::all_sweep_params();
  } else {
    params.push_back(eval::sweep_param_from_string(cmd.param));
  }
  // Every value is checked before the first pair is read.
  std::vector<std::vector<double>> values;
  for (eval::SweepParam p : params) {
    values.push_back(cmd.values.empty() ? eval::default_sweep_values(p, base) : cmd.values);
    for (double v : values.back()) {
      try {
        eval::with_value(base, p, v);
      } catch (const Error& e) {
        throw UsageError(std::string("--values: ") + e.what());
      }
    }
  }
  const std::vector<eval::EvalPair> pairs = sweep_pairs(cmd);
  prepare_out_dir(cmd.out);
  const std::string csv_path = (fs::path(cmd.out) / "sweep.csv").string();

  const pipeline::TbbExecutor executor;
  std::vector<eval::SweepRow> rows;
  std::vector<std::string> written;
  const std::string sub = subtitle(cmd);
  pipeline::run_with_threads(cmd.lk.threads, [&] {
    for (std::size_t k = 0; k < params.size(); ++k) {
      const eval::SweepParam p = params[k];
      const std::size_t n = values[k].size();
      const auto progress = [&](const eval::SweepRow& r, std::size_t i) {
        if (!cmd.progress) return;
        std::cerr << "sweep " << eval::to_string(p) << " " << eval::sweep_value_text(r.value)
                  << " (" << i + 1 << "/" << n << "): AAE " << fixed(r.aae_deg, 3) << " deg, EPE "
                  << fixed(r.epe, 4) << " px, " << fixed(r.ms_per_pair, 2) << " ms/pair"
                  << std::endl;
      };
      const std::vector<eval::SweepRow> part =
          eval::sweep(pairs, base, p, values[k], &executor, progress, cmd.repeats);
      rows.insert(rows.end(), part.begin(), part.end());
      // Written after each parameter, so an interrupted "all" keeps what is complete.
      write_text_atomically(csv_path, eval::sweep_csv(rows));
      const std::string svg =
          (fs::path(cmd.out) / (std::string(eval::to_string(p)) + ".svg")).string();
      report::write_plot_svg(svg, report::sweep_plot(p, rows, sub));
      written.push_back(svg);
    }
  });

  std::cout << "parameter    value      AAE(deg)    EPE(px)  ms/pair\n";
  for (const eval::SweepRow& r : rows) {
    char line[128];
    std::snprintf(line, sizeof line, "%-11s %-9s %9.3f %10.4f %8.2f\n", eval::to_string(r.param),
                  eval::sweep_value_text(r.value).c_str(), r.aae_deg, r.epe, r.ms_per_pair);
    std::cout << line;
  }
  std::string list = csv_path;
  for (const std::string& w : written)
    list += ", " + w;
  std::cout << "swept " << rows.size() << " values over " << pairs.size() << " pairs, "
            << cmd.lk.threads << " threads, time per pair the fastest of " << cmd.repeats
            << (cmd.repeats == 1 ? " run" : " runs") << "; wrote " << list << "\n";
}

int default_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

}  // namespace

void add_sweep_command(CLI::App& app) {
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
