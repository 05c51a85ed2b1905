// The run-time comparison of the paper (Sec. 4.4-4.5, Fig. 12): the same input tracked in local
// mode and in global mode (the whole frame every frame), one run after the other in this
// process, optionally again at several patch sizes. Each run's tracker time per frame gives its
// median, 95th percentile and mean; the speed-up of local mode is global's median over local's.
// write_compare_files writes compare.csv, compare.json, ms_per_frame.svg and, with patch sizes,
// patches.svg; compare_table is the table `roiflow track --compare` prints.
//
//   roiflow::pipeline::CompareOptions options;
//   options.input = "car.mp4";
//   options.out_dir = "out/compare";  // also gets {local,global}.{csv,json}, each run's log
//   options.patches = {6, 10, 14};
//   const roiflow::pipeline::CompareResult r = roiflow::pipeline::run_compare(options);
//   if (!r.cancelled) std::cout << roiflow::pipeline::compare_table(r, options);
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/run.hpp"
#include "pipeline/signals.hpp"

namespace roiflow::pipeline {

struct CompareOptions {
  std::string input;  // a video file or an image folder (a camera would differ between runs)
  SourceOptions source;
  TrackRunOptions run;  // the tracker (its mode is set per run), threads, cancel; log, video
                        // and keep_records are set per run
  std::string preset = "paper";  // for the record in compare.json
  std::vector<int> patches;      // more patch sizes to compare at
  std::string out_dir;           // created if missing
};

struct CompareRun {
  std::string mode;
  int patch = 0;
  TrackSummary summary;
  std::vector<double> ms;  // tracker time of every frame
  double ms_median = 0, ms_p95 = 0, ms_mean = 0;
};

struct CompareResult {
  CompareRun local, global;
  std::vector<std::pair<CompareRun, CompareRun>> patches;  // local, global per patch size
  bool cancelled = false;                                  // the runs were cut short
};

// Runs every mode and patch size. Throws UsageError for a camera input or an init box outside
// the frame (before any run), roiflow::Error naming the run when its input stops mid-stream, and
// for an out_dir that is not a directory.
CompareResult run_compare(const CompareOptions& options);
// ms per frame (median) of global over local: how many times faster local mode is.
double speedup(const CompareRun& local, const CompareRun& global);
// Writes the comparison's files into options.out_dir; returns their paths.
std::vector<std::string> write_compare_files(const CompareResult& r, const CompareOptions& options);
std::string compare_table(const CompareResult& r, const CompareOptions& options);
// What `roiflow track --compare` prints: the table, the files written, where each mode's log and
// summary went.
std::string compare_text(const CompareResult& r, const CompareOptions& options,
                         const std::vector<std::string>& written);
// After a cancelled comparison: 128 + the signal, "interrupted by SIGINT during the compare
// runs; no comparison written"; else exit code 0.
Ending compare_ending(const CompareResult& r);

}  // namespace roiflow::pipeline
