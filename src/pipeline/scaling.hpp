// Thread scaling: the same run over the same input at several thread counts, and how its
// throughput grows (speedup and parallel efficiency), as a table and an SVG plot.
//
//   #include "core/atomic_write.hpp"
//   using namespace roiflow;
//   pipeline::ScalingOptions o;
//   o.input = "synthetic:300:640x480:16";
//   o.threads = {1, 2, 4};
//   o.mode = pipeline::ScalingMode::Local;
//   const pipeline::ScalingResult r = pipeline::run_scaling(o);
//   roiflow::write_text_atomically("out/scaling.csv", pipeline::scaling_csv(r));
//   report::write_plot_svg("out/scaling.svg", pipeline::scaling_plot(r));
//
// Each thread count gets its own runs: a fresh VideoSource, a fresh tracker, one oneTBB arena
// of that many slots (pipeline::GraphOptions::threads) under a tbb::global_control that caps
// oneTBB's parallelism at that count, and no sink (no file is written, nothing but the work is
// timed). The work per mode:
//  - Local: fixed-camera tracking of every moving object (pipeline::track_objects, as
//    `roiflow track` without --init): motion detection, per-object LK tiles, decisions.
//  - Global: the single-object tracker (tracking::Tracker) with the global treatment on every
//    frame.
//  - Dense: dense LK between every pair of frames (run_dense).
// fps is frames (dense: pairs) per second of wall time; tracker_fps counts only the time inside
// the tracker's stages (local: the multi-object graph's pyramid, background, global, plan,
// lk and decide; global: pyramid + track; dense: flow), summed over the frames.
// speedup = fps / fps of the first row (the smallest thread count, normally 1); efficiency =
// speedup x (first row's threads / threads). With `repeats` > 1 each count keeps its fastest run
// (least wall time): on a shared machine the fastest run is the one least disturbed.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "flow/dense_lk.hpp"
#include "report/plot.hpp"

namespace roiflow::pipeline {

enum class ScalingMode { Local, Global, Dense };
const char* to_string(ScalingMode mode);
// "local" | "global" | "dense"; throws roiflow::Error for anything else.
ScalingMode scaling_mode_from_string(const std::string& text);

struct ScalingOptions {
  std::string input;         // anything video::VideoSource opens (synthetic:... included)
  std::vector<int> threads;  // thread counts, each 1..kMaxThreads, no repeats; run in this order
  ScalingMode mode = ScalingMode::Local;
  flow::LkParams lk = flow::LkParams::paper();
  long long max_frames = 0;  // 0 = the whole input
  int repeats = 1;           // runs per thread count, the fastest kept; 1..100
  const std::atomic<bool>* cancel = nullptr;
  void validate() const;  // throws roiflow::Error naming the bad value
};

struct ScalingRow {
  int threads = 0;
  long long frames = 0;  // frames (dense: pairs) of the kept run
  double wall_s = 0;
  double fps = 0;
  double tracker_fps = 0;
  double speedup = 0;
  double efficiency = 0;
};

struct ScalingResult {
  std::string input;  // the source's description
  ScalingMode mode = ScalingMode::Local;
  std::vector<ScalingRow> rows;  // in the order of ScalingOptions::threads
  bool cancelled = false;        // *cancel became true; rows holds the counts finished before
};

// Throws roiflow::Error for bad options or an input that does not open, and what a run throws.
ScalingResult run_scaling(const ScalingOptions& options);

// Derives speedup and efficiency of every row from fps and threads (run_scaling does this).
void fill_speedup(std::vector<ScalingRow>& rows);

// "threads,fps,tracker_fps,speedup,efficiency" and one line per row.
std::string scaling_csv(const ScalingResult& result);
// Two panels over threads: fps and tracker fps above; speedup (with the ideal line) below.
report::Plot scaling_plot(const ScalingResult& result);
// Writes DIR/scaling.csv and DIR/scaling.svg (DIR must exist); returns their paths.
std::vector<std::string> write_scaling(const ScalingResult& result, const std::string& dir);
// What `roiflow scaling` prints: the mode and input, then a table of the rows.
std::string scaling_text(const ScalingResult& result);

}  // namespace roiflow::pipeline
