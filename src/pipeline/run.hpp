// Whole runs over a video: the source, the graph, the sinks and a typed summary, for the
// `roiflow track` and `roiflow dense` commands and for any program that wants the same runs.
// run_track_video tracks one object through a stream and writes the track log and the annotated
// video it is asked for; run_dense_video writes the colour-coded dense flow of every frame pair.
// Each returns what the run measured (frames, rates, per-stage times, peak memory, how it ended);
// turning that into text or JSON is the caller's business.
//
//   roiflow::video::VideoSource source("car.mp4", roiflow::pipeline::source_params({}));
//   roiflow::pipeline::TrackRunOptions options;
//   options.tracker.init = cv::Rect2f(10, 20, 40, 30);
//   options.log = "track.csv";
//   const roiflow::pipeline::TrackSummary s = roiflow::pipeline::run_track_video(source, options);
//   if (s.end == roiflow::pipeline::RunEnd::InputStopped) std::cerr << s.status << "\n";
#pragma once

#include <atomic>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/track_log.hpp"
#include "pipeline/frame_graph.hpp"
#include "report/run_stats.hpp"
#include "tracking/tracker.hpp"
#include "video/flow_file_sink.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {

// What to read of an input.
struct SourceOptions {
  long long start = 0;       // index of the first frame
  long long max_frames = 0;  // 0 = all
  int decode_threads = 0;    // a video's FFmpeg decoder threads; 0 = automatic
};
// The VideoSource parameters of a run: colour is converted only for the frames that need it.
video::VideoSourceParams source_params(const SourceOptions& options);

// A stream that is not a VideoSource (a generated scene): its frames and what a run must know.
struct StreamInfo {
  cv::Size size;
  double fps = 25;
  long long frame_hint = -1;  // frames expected; -1 unknown
  std::string description;
};

// How a run ended.
enum class RunEnd {
  Complete,      // end of the input, or max_frames reached
  Cancelled,     // *cancel became true; the frames in flight were finished
  InputStopped,  // the input broke mid-stream (VideoSource's STOP policy); outputs hold the rest
};

struct TrackRunOptions {
  tracking::TrackerParams tracker;
  int threads = 1;
  int max_in_flight = 0;      // frames decoded ahead at most; 0 = 2 x threads + 2
  std::string log;            // track log (.csv or .json); empty = none
  std::string video;          // annotated video, or a folder of PNGs; empty = none
  bool progress = false;      // progress bar on stderr (only when it is a terminal)
  bool keep_records = false;  // keep every frame's record in the summary
  const std::atomic<bool>* cancel = nullptr;
};

struct TrackSummary {
  std::string mode;   // "local" | "global"
  std::string input;  // the source's description
  RunEnd end = RunEnd::Complete;
  std::string status;  // the source's last status ("end of stream", "stopped at frame N: ...")
  long long frames = 0;
  long long global_activations = 0;
  long long lost_frames = 0;
  double fps = 0;                   // frames per second of wall time
  double tracker_fps = 0;           // frames per second of tracker time (pyramid + track)
  double tracker_ms_per_frame = 0;  // decode excluded
  double wall_s = 0;
  int threads = 0;
  int roi = 0;
  long long max_in_flight = 0;
  double peak_rss_mb = 0;  // of the process, after the run
  std::vector<report::StageTotal> stages;
  std::vector<eval::TrackRecord> records;  // with keep_records
};

// Throws UsageError, before the first frame is tracked, when less than 2x2 pixels of
// options.tracker.init lie inside the frame.
TrackSummary run_track_video(video::VideoSource& source, const TrackRunOptions& options);
TrackSummary run_track_stream(const FrameSource& frames, const StreamInfo& info,
                              const TrackRunOptions& options);
// Throws UsageError when less than `min_side` x `min_side` pixels of `init` (any part of it when
// min_side is 0) lie inside a frame of `size`.
void check_init_inside(const std::optional<cv::Rect2f>& init, cv::Size size, float min_side);
// A track run's outputs, checked before any work: the track log `log` (--log), the annotated
// `video` (--out), the `summary` (--summary) and a multi-object run's `mot` (--mot); empty ones
// are not written. Throws roiflow::Error naming the option.
void check_track_outputs(const std::string& log, const std::string& video,
                         const std::string& summary, const std::string& mot = "");

struct DenseRunOptions {
  flow::LkParams lk = flow::LkParams::paper();
  int threads = 1;
  int max_in_flight = 0;
  std::string video;     // colour-coded flow: a video or a folder of PNGs; empty = none
  std::string flow_dir;  // raw flow, one file per pair; empty = none (one of the two is needed)
  video::FlowFileFormat flow_format = video::FlowFileFormat::Flo;
  double max_motion = 0;  // pixels at full colour saturation; 0 = each pair's robust maximum
  bool progress = false;
  const std::atomic<bool>* cancel = nullptr;
};

struct DenseSummary {
  std::string input;
  std::string outputs;  // what was written (DenseOutputs::description)
  RunEnd end = RunEnd::Complete;
  std::string status;
  long long frames = 0;
  long long pairs = 0;
  double fps = 0;  // pairs per second of wall time
  double flow_ms_per_pair = 0;
  double wall_s = 0;
  int threads = 0;
  double peak_rss_mb = 0;
  std::vector<report::StageTotal> stages;
};

DenseSummary run_dense_video(video::VideoSource& source, const DenseRunOptions& options);

}  // namespace roiflow::pipeline
