// roiflow benchmark: OTB one-pass evaluation of several trackers (pipeline/benchmark.hpp).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/benchmark.hpp"
#include "tracking/box_tracker.hpp"

namespace roiflow::cli {

void add_benchmark_command(CLI::App& app, int& /*exit_code*/) {
  static LkOptions lk;
  static std::string out;
  static bool tracks = false, progress = true;
  static pipeline::BenchmarkOptions run;  // DIR, --trackers, --sequences, --max-frames, --roi, ...
  run.trackers = {"roiflow", "csrt", "kcf", "mosse", "medianflow"};
  CLI::App* sub = app.add_subcommand(
      "benchmark",
      "OTB one-pass evaluation of roiflow and OpenCV's trackers over a folder of sequences: "
      "AUC, precision@20, mean IoU, frames/s; Markdown, CSV and SVG plots");
  sub->add_option("DIR", run.dir,
                  "OTB-layout folder, <seq>/img/*.jpg and <seq>/groundtruth_rect.txt (NaN "
                  "lines not scored), or one sequence folder (docs/BENCHMARK.md)")
      ->required();
  sub->add_option("--out", out, "folder for benchmark.md/.csv, success.svg, precision.svg")
      ->required();
  sub->add_option("--trackers", run.trackers, "trackers to run, in the order to report")
      ->type_name("LIST")
      ->delimiter(',')
      ->check([](const std::string& t) { return tracking::box_tracker_check(t); })
      ->capture_default_str();
  sub->add_option("--sequences", run.sequences, "only these sequences (folders)")->delimiter(',');
  sub->add_option("--max-frames", run.max_frames, "at most N frames of each sequence (0 = all)")
      ->check(CLI::Range(0LL, 1000000000LL));
  static std::pair<float, float> shift;
  sub->add_option("--init-shift", shift, "start from the first box moved DX,DY px")->delimiter(',');
  add_tracker_options(*sub, run.roiflow, nullptr, "roiflow: ");
  sub->add_flag("--tracks", tracks, "also write the track logs, OUT/tracks/<seq>/<tracker>.csv");
  sub->add_flag("!--no-progress", progress, "no line per finished sequence on stderr");
  lk.threads = pipeline::default_threads();
  add_lk_options(*sub, lk);
  sub->get_option("--threads")->description("sequences at once (each tracker call: one thread)");
  sub->callback([] {
    pipeline::BenchmarkOptions o = run;
    o.threads = lk.threads;
    o.init_shift = {shift.first, shift.second};
    o.roiflow.lk = lk_params(lk);
    as_usage([&] { o.roiflow.validate(); });
    pipeline::check_benchmark_out(out);
    if (progress) {
      o.on_sequence = [](const std::string& line) { std::cerr << "benchmark: " << line << "\n"; };
    }
    const pipeline::BenchmarkResult result = pipeline::run_benchmark(o);
    const std::vector<std::string> written = pipeline::write_benchmark(result, out, tracks);
    std::cout << pipeline::benchmark_text(result, o.threads, written);
  });
}

}  // namespace roiflow::cli
