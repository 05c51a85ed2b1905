// The oneTBB flow graphs that run roiflow over a video. Tracking mode: decoding and pyramids of
// later frames run ahead of the serial tracker, bounded by a limiter (at most `max_in_flight`
// frames alive), and every sink sees every frame once, in order. Dense mode: each frame is
// paired with the previous one, several pairs' flow and the sinks' parallel parts
// (FlowSink::prepare) run at once, and the sinks' ordered parts see the pairs in order.
// An exception anywhere cancels the graph and is rethrown once the running nodes are done; a
// cancel flag stops the source and finishes the frames in flight. docs/ARCHITECTURE.md, "The
// graphs", draws them.
//
//   roiflow::video::VideoSource source("car.mp4");
//   roiflow::pipeline::TbbExecutor tiles;  // LK over row tiles of the region
//   roiflow::tracking::Tracker tracker(roiflow::tracking::TrackerParams{}, &tiles);
//   roiflow::pipeline::GraphOptions options;
//   options.threads = 4;
//   const roiflow::pipeline::RunReport report = roiflow::pipeline::run_tracking(
//       [&] { return source.next(); }, tracker,
//       {{"print", [](const roiflow::pipeline::TrackedFrame& f) { std::cout << f.seq << "\n"; }}},
//       options);
//   std::cout << report.frames << " frames in " << report.wall_s << " s\n";
//   #include "pipeline/tbb_executor.hpp"
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "report/run_stats.hpp"
#include "tracking/multi_tracker.hpp"
#include "tracking/tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {

// Frames in order; std::nullopt at the end. Called from one thread at a time.
using FrameSource = std::function<std::optional<video::Frame>()>;

// The stages a test hook sees, in the order a frame meets them.
enum class Stage { Source, Pyramid, Track, Flow, Sink };

struct GraphOptions {
  int threads = 0;        // worker threads (a task_arena of this size); 0 = all hardware threads
  int max_in_flight = 0;  // frames between source and retirement; 0 = 2 * threads + 2
  const std::atomic<bool>* cancel = nullptr;  // set to stop reading; frames in flight finish
  report::RunStats* stats = nullptr;          // per-stage times ("decode", "pyramid", ...)
  // Called at the start of every stage body with the frame's sequence number (tests inject
  // delays and failures here). Must be thread-safe.
  std::function<void(Stage, long long seq)> on_stage;
};

struct RunReport {
  long long frames = 0;         // frames that went through the whole graph
  long long max_in_flight = 0;  // the most frames alive at once (never above the limit)
  bool cancelled = false;
  double wall_s = 0;
};

// ------------------------------------------------------------------------------- tracking mode

struct TrackedFrame {
  long long seq = 0;  // 0-based order of arrival from the source
  std::shared_ptr<const video::Frame> frame;
  std::shared_ptr<const tracking::TrackerOutput> output;
};

struct TrackSink {
  std::string name;  // for statistics: "log", "video", ...
  std::function<void(const TrackedFrame&)> consume;
};

RunReport run_tracking(const FrameSource& source, tracking::Tracker& tracker,
                       const std::vector<TrackSink>& sinks, const GraphOptions& options = {});

// The same with any serial per-frame step in the tracker's place (it gets each frame with its
// pyramid of `levels` levels smoothed by `sigma`, in order).
struct TrackStep {
  int levels = 3;
  double sigma = 0.5;
  std::function<tracking::TrackerOutput(const tracking::TrackerInput&)> process;
  // Optional, thread-safe: false when the step does not want whole-frame pyramids for the next
  // frames (Tracker::wants_pyramid); those frames then come with a null pyramid. Empty: always.
  std::function<bool()> wants_pyramid;
  // Optional: waits for work `process` left running on the graph's threads
  // (Tracker::finish_background_work); called once the graph is done, before its threads go,
  // also when the run ends by an exception.
  std::function<void()> drain;
};
RunReport run_tracking(const FrameSource& source, const TrackStep& step,
                       const std::vector<TrackSink>& sinks, const GraphOptions& options = {});

// ---------------------------------------------------------------------------------- dense mode

struct FlowPair {
  long long seq = 0;  // sequence number of frame t (the first pair is 0)
  std::shared_ptr<const video::Frame> frame_t;
  std::shared_ptr<const video::Frame> frame_t1;
  std::shared_ptr<const flow::FlowResult> flow;  // whole-frame flow t -> t+1
  // In FlowSink::consume: what that sink's `prepare` made of this pair (empty without one).
  cv::Mat prepared = {};
};

// A sink of dense mode in two parts. `prepare` (optional, thread-safe) is the costly, parallel
// part, e.g. colour coding and PNG encoding: it runs on several pairs at once, in any order, as
// soon as a pair's flow exists (its time is the "<name>.prepare" stage). `consume` is the
// ordered part, e.g. the write: one pair at a time, in pair order, with FlowPair::prepared set
// to what `prepare` returned for that pair.
struct FlowSink {
  std::string name;
  std::function<void(const FlowPair&)> consume;
  std::function<cv::Mat(const FlowPair&)> prepare = {};
};

RunReport run_dense(const FrameSource& source, const flow::LkParams& params,
                    const std::vector<FlowSink>& sinks, const GraphOptions& options = {});

// ------------------------------------------------------------------- multi-object tracking mode
//
// Every moving object of a fixed camera (tracking/multi_tracker.hpp), on this graph:
//
//   front end ─► background (serial: MOG2 refresh) ─► global (detect_objects) ─► sequencer ─┐
//                                                                                           ▼
//          ┌──────────────── decisions at t (feedback edge) ─────────────────────► join (t+1, t)
//          │                                                                                │
//   decision (serial) ◄─ collect (serial, per frame) ◄─ LK tiles (parallel) ◄─ plan (serial)◄┘
//          │
//          └─► sequencer ─► sinks ─► retire ─► limiter
//
// The plan node pairs frame t+1 with the decisions at t (a queueing join: the decisions come
// back on an edge, nothing is kept in a node) and puts one task per tile of every object's
// region; the tiles of a frame run at once and a serial node joins them per frame before the
// decision. The background refresh and the global treatment of later frames run beside the
// LK tiles and decisions of earlier ones (pipelined), bounded by the limiter.

struct MotTrackedFrame {
  long long seq = 0;
  std::shared_ptr<const video::Frame> frame;
  std::shared_ptr<const tracking::MotFrame> output;
};

struct MotSink {
  std::string name;
  std::function<void(const MotTrackedFrame&)> consume;
};

// Stage times in options.stats: "pyramid", "background", "global", "plan", "lk", "decide".
RunReport run_mot(const FrameSource& source, const tracking::MultiTrackerParams& params,
                  const std::vector<MotSink>& sinks, const GraphOptions& options = {});

const char* to_string(Stage stage);

}  // namespace roiflow::pipeline
