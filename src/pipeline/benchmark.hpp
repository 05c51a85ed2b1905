// One-pass evaluation (OPE) of several single-object trackers over every sequence of an
// OTB-layout folder: `roiflow benchmark`'s run.
//
//   using namespace roiflow;
//   pipeline::BenchmarkOptions options;
//   options.dir = "data/tracking";                        // <seq>/img/*.jpg + groundtruth_rect.txt
//   options.trackers = {"roiflow", "csrt"};
//   options.threads = 2;                                  // sequences at once
//   const pipeline::BenchmarkResult result = pipeline::run_benchmark(options);
//   pipeline::write_benchmark(result, "out/bench");       // benchmark.md/.csv,
//   success/precision.svg
//
// Every tracker starts from the first ground-truth box of each sequence and then sees every
// frame once (OTB's OPE; stages/box_tracker.hpp runs each). Each sequence is decoded once and
// every tracker is given each frame in turn, so all see the same frames under the same load.
// Sequences run in parallel on a oneTBB arena of `threads` threads; inside a sequence the work is
// serial: roiflow's tracker gets no executor and OpenCV is held at one thread for the run. Each
// tracker call is timed with the calling thread's CPU clock (CLOCK_THREAD_CPUTIME_ID), so frames/s
// is single-threaded tracker time, decoding and colour conversion excluded, and is the same
// whether sequences run in parallel or one after the other (up to cache and memory contention,
// which every tracker of a sequence shares).
//
// Everything is checked before any tracker runs: the trackers' names (known, not repeated), the
// folder and its sequences (ground truth readable, its first box present and inside the first
// frame, one box per frame), `sequences` (each must exist). A frame that cannot be decoded
// mid-run fails the run. All failures throw roiflow::Error with one line naming the cause.
// write_benchmark() writes only after the whole run succeeded, each file atomically.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "eval/otb_benchmark.hpp"
#include "stages/tracker.hpp"

namespace roiflow::pipeline {

struct BenchmarkOptions {
  std::string dir;                     // OTB-layout folder, or one sequence's folder
  std::vector<std::string> trackers;   // stages::box_tracker_names(), in the order to report
  std::vector<std::string> sequences;  // only these (folder names); empty = all
  int threads = 1;                     // sequences run at once, 1..256
  long long max_frames = 0;            // at most this many frames of each sequence; 0 = all
  stages::TrackerParams roiflow;       // roiflow's settings (init is set per sequence)
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

}  // namespace roiflow::pipeline
