// roiflow benchmark: OTB one-pass evaluation of roiflow and OpenCV's trackers over every sequence
// of a folder, in one run (pipeline/benchmark.hpp).
//
//   roiflow benchmark data/tracking --out out/bench --trackers roiflow,csrt,kcf,mosse,medianflow
//   -> out/bench/benchmark.md, benchmark.csv, success.svg, precision.svg; the table on stdout
//   roiflow benchmark data/tracking --out out/bench --trackers roiflow --tracks   # + track logs
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.hpp"
#include "pipeline/benchmark.hpp"
#include "pipeline/tbb_executor.hpp"
#include "stages/box_tracker.hpp"

namespace roiflow::cli {
namespace {

struct BenchmarkCommand {
  LkOptions lk;
  std::string dir;
  std::string out;
  std::vector<std::string> trackers = {"roiflow", "csrt", "kcf", "mosse", "medianflow"};
  std::vector<std::string> sequences;
  long long max_frames = 0;
  int roi = stages::TrackerParams{}.roi;
  double lk_patches = stages::LocalTrackerParams{}.lk_patches;
  bool progress = true;
  bool tracks = false;
};

void run_benchmark_command(const BenchmarkCommand& cmd) {
  pipeline::BenchmarkOptions options;
  options.dir = cmd.dir;
  options.trackers = cmd.trackers;
  options.sequences = cmd.sequences;
  options.threads = cmd.lk.threads;
  options.max_frames = cmd.max_frames;
  options.roiflow.lk = lk_params(cmd.lk);
  options.roiflow.roi = cmd.roi;
  options.roiflow.local.lk_patches = cmd.lk_patches;
  try {
    options.roiflow.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  for (const std::string& t : cmd.trackers) {
    const auto& known = stages::box_tracker_names();
    if (std::find(known.begin(), known.end(), t) == known.end()) {
      std::string list;
      for (const std::string& k : known)
        list += (list.empty() ? "" : ",") + k;
      throw UsageError("--trackers: unknown tracker '" + t + "' (known: " + list + ")");
    }
  }
  pipeline::check_benchmark_out(cmd.out);
  if (cmd.progress) {
    options.on_sequence = [](const std::string& line) {
      std::cerr << "benchmark: " << line << "\n";
    };
  }
  const pipeline::BenchmarkResult result = pipeline::run_benchmark(options);
  const std::vector<std::string> written = pipeline::write_benchmark(result, cmd.out, cmd.tracks);
  std::cout << eval::format_benchmark_markdown(result.rows, result.means) << "\n";
  std::string list;
  for (const std::string& w : written)
    list += (list.empty() ? "" : ", ") + w;
  std::cout << "benchmarked " << result.means.size() << " trackers on "
            << result.rows.size() / std::max<std::size_t>(1, result.means.size()) << " sequences, "
            << options.threads << " at once; wrote " << list << "\n";
}

int hardware_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

}  // namespace

void add_benchmark_command(CLI::App& app) {
  static BenchmarkCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "benchmark",
      "OTB one-pass evaluation of roiflow and OpenCV's trackers over a folder of sequences: "
      "AUC, precision@20, mean IoU, frames/s; Markdown, CSV and SVG plots");
  sub->add_option("DIR", cmd.dir,
                  "OTB-layout folder: <seq>/img/0001.jpg ... and <seq>/groundtruth_rect.txt "
                  "(x,y,w,h, or TinyTLP's 6 columns; NaN lines = target absent, not scored); "
                  "or one such sequence folder")
      ->type_name("DIR")
      ->required();
  sub->add_option("--out", cmd.out,
                  "folder for benchmark.md, benchmark.csv, success.svg, precision.svg (created "
                  "if missing)")
      ->type_name("DIR")
      ->required();
  sub->add_option("--trackers", cmd.trackers, "trackers to run, in the order to report")
      ->type_name("LIST")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--sequences", cmd.sequences, "only these sequences (folder names)")
      ->type_name("LIST")
      ->delimiter(',');
  sub->add_option("--max-frames", cmd.max_frames,
                  "at most N frames of each sequence, scored as a prefix (0 = all)")
      ->type_name("N")
      ->check(CLI::Range(0LL, 1000000000LL));
  sub->add_option("--roi", cmd.roi, "roiflow: side of the local region in pixels")
      ->check(CLI::Range(8, 4096))
      ->capture_default_str();
  sub->add_option("--lk-patches", cmd.lk_patches,
                  "roiflow: LK's pyramid level keeps this many LK patches across the object "
                  "(0 = always full resolution)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  sub->add_flag(
      "--tracks", cmd.tracks,
      "also write every run's track log, OUT/tracks/<sequence>/<tracker>.csv (the format of "
      "roiflow track --log; roiflow score reads it)");
  sub->add_flag("!--no-progress", cmd.progress, "no line per finished sequence on stderr");
  cmd.lk.threads = hardware_threads();
  add_lk_options(*sub, cmd.lk);
  sub->get_option("--threads")
      ->description(
          "sequences run at once; every tracker call is single-threaded and timed with its "
          "thread's CPU clock, so frames/s does not depend on it");
  sub->callback([] { run_benchmark_command(cmd); });
}

}  // namespace roiflow::cli
