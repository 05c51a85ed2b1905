// One-pass evaluation (OPE) of several single-object trackers over every sequence of an
// OTB-layout folder, `roiflow benchmark`'s run: every tracker starts from each sequence's first
// ground-truth box and sees every frame once, each sequence decoded once, sequences in
// parallel, each tracker call timed on its thread's CPU clock (docs/BENCHMARK.md).
//
//   roiflow::pipeline::BenchmarkOptions options;
//   options.dir = "data/tracking";  // <seq>/img/*.jpg + groundtruth_rect.txt
//   options.trackers = {"roiflow", "csrt"};
//   options.threads = 2;  // sequences at once
//   const roiflow::pipeline::BenchmarkResult result = roiflow::pipeline::run_benchmark(options);
//   roiflow::pipeline::write_benchmark(result, "out/bench");  // benchmark.md/.csv, plots
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "eval/otb_benchmark.hpp"
#include "tracking/tracker.hpp"

namespace roiflow::pipeline {

struct BenchmarkOptions {
  std::string dir;                     // OTB-layout folder, or one sequence's folder
  std::vector<std::string> trackers;   // tracking::box_tracker_names(), in the order to report
  std::vector<std::string> sequences;  // only these (folder names); empty = all
  int threads = 1;                     // sequences run at once, 1..256
  long long max_frames = 0;            // at most this many frames of each sequence; 0 = all
  tracking::TrackerParams roiflow;     // roiflow's settings (init is set per sequence)
  // Every tracker starts from the first ground-truth box moved by this many pixels (scoring
  // still uses the true boxes): OTB's spatial-robustness check, |each| <= 1000.
  cv::Point2f init_shift;
  // Called after each sequence, from the thread that ran it (one call at a time), with e.g.
  // "DragonBaby: 113 frames, 5 trackers".
  std::function<void(const std::string&)> on_sequence;
};

struct BenchmarkResult {
  std::vector<eval::BenchmarkRow> rows;   // sequence by sequence (sorted), trackers in order
  std::vector<eval::BenchmarkRow> means;  // one per tracker, in order
  std::vector<std::string> skipped;       // sub-folders that are not sequences
  std::vector<eval::TrackerRun> runs;     // what each row's tracker reported, row by row
};

// Throws roiflow::Error before any work on bad options or input (see above).
BenchmarkResult run_benchmark(const BenchmarkOptions& options);

// Throws roiflow::Error when `out_dir` exists and is not a directory, or when no directory can be
// made there (its nearest existing ancestor is not a writable directory). Run before
// run_benchmark() so that a mistyped --out fails at once.
void check_benchmark_out(const std::string& out_dir);

// Writes out_dir/benchmark.md, benchmark.csv, success.svg and precision.svg (made if missing),
// each atomically; with `tracks`, also every run's track log as
// out_dir/tracks/<sequence>/<tracker>.csv (eval::track_log_csv). Returns the paths of the four
// files, then the tracks folder when written.
std::vector<std::string> write_benchmark(const BenchmarkResult& result, const std::string& out_dir,
                                         bool tracks = false);

// What `roiflow benchmark` prints: the Markdown table, then "benchmarked T trackers on S
// sequences, N at once; wrote FILES".
std::string benchmark_text(const BenchmarkResult& result, int threads,
                           const std::vector<std::string>& written);

}  // namespace roiflow::pipeline
