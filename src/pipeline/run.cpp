#include "pipeline/run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <optional>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "pipeline/dense_outputs.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/annotate.hpp"
#include "report/progress.hpp"
#include "video/track_log_sink.hpp"
#include "video/video_sink.hpp"

namespace roiflow::pipeline {
namespace {

double stage_ms(const std::vector<report::StageTotal>& stages, const char* name) {
  for (const report::StageTotal& s : stages) {
    if (s.name == name) return s.ms_total;
  }
  return 0.0;
}

report::TrackAnnotation track_annotation(const tracking::TrackerOutput& out) {
  report::TrackAnnotation a;
  a.index = out.index;
  a.has_target = out.has_target;
  a.box = out.box;
  a.velocity = out.velocity;
  a.global = out.mode == eval::TrackRecord::Mode::Global;
  a.lost = out.lost;
  a.region = out.region;
  a.region_flow = out.region_flow;
  return a;
}

GraphOptions graph_options(int threads, int max_in_flight, const std::atomic<bool>* cancel,
                           report::RunStats* stats) {
  GraphOptions options;
  options.threads = threads;
  options.max_in_flight = max_in_flight;
  options.cancel = cancel;
  options.stats = stats;
  return options;
}

RunEnd run_end(const RunReport& report, const video::SourceStatus* status) {
  if (report.cancelled) return RunEnd::Cancelled;
  if (status != nullptr && status->state == video::SourceStatus::State::kStopped) {
    return RunEnd::InputStopped;
  }
  return RunEnd::Complete;
}

}  // namespace

video::VideoSourceParams source_params(const SourceOptions& options) {
  video::VideoSourceParams p;
  p.start = options.start;
  p.max_frames = options.max_frames;
  p.decode_threads = options.decode_threads;
  // Colour is converted only for the frames that need it: the video sink's and the few the
  // tracker learns appearance or background from (Frame::picture()).
  p.defer_colour = true;
  return p;
}

TrackSummary run_track_stream(const FrameSource& frames, const StreamInfo& info,
                              const TrackRunOptions& options) {
  TbbExecutor tiles;
  tracking::Tracker tracker(options.tracker, &tiles);
  std::optional<video::TrackLogWriter> log;
  if (!options.log.empty()) log.emplace(options.log);
  std::optional<video::VideoSink> video;
  if (!options.video.empty()) video.emplace(options.video, info.fps, info.size);
  report::Progress progress(std::cerr, info.frame_hint,
                            options.progress && report::Progress::stderr_is_terminal());

  TrackSummary s;
  std::vector<TrackSink> sinks;
  sinks.push_back({"log", [&](const TrackedFrame& f) {
                     const eval::TrackRecord r = f.output->record();
                     if (r.lost) ++s.lost_frames;
                     if (log) log->write(r);
                     if (options.keep_records) s.records.push_back(r);
                   }});
  if (video) {
    sinks.push_back({"video", [&](const TrackedFrame& f) {
                       video->write(
                           report::annotate_frame(f.frame->picture(), track_annotation(*f.output)));
                     }});
  }
  sinks.push_back({"progress", [&](const TrackedFrame& f) { progress.update(f.seq + 1); }});

  report::RunStats stats;
  const RunReport report =
      run_tracking(frames, tracker, sinks,
                   graph_options(options.threads, options.max_in_flight, options.cancel, &stats));
  progress.finish();
  if (log) log->close();
  if (video) video->close();

  s.stages = stats.totals();
  const double tracker_ms = stage_ms(s.stages, "pyramid") + stage_ms(s.stages, "track");
  s.mode = tracking::to_string(options.tracker.mode);
  s.input = info.description;
  s.end = run_end(report, nullptr);
  s.frames = report.frames;
  s.global_activations = tracker.global_activations();
  s.fps = report.wall_s > 0 ? static_cast<double>(report.frames) / report.wall_s : 0.0;
  s.tracker_fps = tracker_ms > 0 ? static_cast<double>(report.frames) / (tracker_ms / 1000.0) : 0.0;
  s.tracker_ms_per_frame =
      report.frames > 0 ? tracker_ms / static_cast<double>(report.frames) : 0.0;
  s.wall_s = report.wall_s;
  s.threads = options.threads;
  s.roi = options.tracker.roi;
  s.max_in_flight = report.max_in_flight;
  s.peak_rss_mb = report::peak_rss_mb();
  return s;
}

void check_init_inside(const std::optional<cv::Rect2f>& init, cv::Size size, float min_side) {
  if (!init) return;
  const cv::Rect2f inside =
      *init & cv::Rect2f(0.f, 0.f, static_cast<float>(size.width), static_cast<float>(size.height));
  if (inside.width < min_side || inside.height < min_side || inside.area() <= 0.f) {
    throw UsageError(
        fmt::format("--init: the box {},{},{},{} lies outside the {} frame{}", number_text(init->x),
                    number_text(init->y), number_text(init->width), number_text(init->height),
                    size_text(size), min_side > 0 ? " (less than 2x2 pixels of it inside)" : ""));
  }
}

TrackSummary run_track_video(video::VideoSource& source, const TrackRunOptions& options) {
  check_init_inside(options.tracker.init, source.size(), 2.f);
  const StreamInfo info{source.size(), source.fps(), source.frame_count_hint(),
                        source.description()};
  TrackSummary s = run_track_stream([&] { return source.next(); }, info, options);
  if (s.end == RunEnd::Complete && source.status().state == video::SourceStatus::State::kStopped) {
    s.end = RunEnd::InputStopped;
  }
  s.status = source.status().message;
  return s;
}

void check_track_outputs(const std::string& log, const std::string& video,
                         const std::string& summary, const std::string& mot) {
  if (!log.empty()) video::check_track_log_path(log, "--log");
  for (const auto& [path, option] :
       {std::pair{&mot, "--mot"}, {&video, "--out"}, {&summary, "--summary"}}) {
    if (!path->empty()) check_output_path(*path, option);
  }
}

DenseSummary run_dense_video(video::VideoSource& source, const DenseRunOptions& options) {
  DenseOutputOptions wanted;
  wanted.video = options.video;
  wanted.flow_dir = options.flow_dir;
  wanted.flow_format = options.flow_format;
  wanted.max_motion = options.max_motion;
  DenseOutputs outputs(wanted, source.fps(), source.size());
  std::vector<FlowSink> sinks = outputs.sinks();
  const long long hint = source.frame_count_hint();
  report::Progress progress(std::cerr, hint > 1 ? hint - 1 : hint,
                            options.progress && report::Progress::stderr_is_terminal());
  sinks.push_back({"progress", [&](const FlowPair& p) { progress.update(p.seq + 1); }});
  report::RunStats stats;
  const RunReport report =
      run_dense([&] { return source.next(); }, options.lk, sinks,
                graph_options(options.threads, options.max_in_flight, options.cancel, &stats));
  progress.finish();
  outputs.close();

  DenseSummary s;
  s.stages = stats.totals();
  s.input = source.description();
  s.outputs = outputs.description();
  s.end = run_end(report, &source.status());
  s.status = source.status().message;
  s.frames = report.frames;
  s.pairs = std::max(0LL, report.frames - 1);
  s.fps = report.wall_s > 0 ? static_cast<double>(s.pairs) / report.wall_s : 0.0;
  s.flow_ms_per_pair =
      s.pairs > 0 ? stage_ms(s.stages, "flow") / static_cast<double>(s.pairs) : 0.0;
  s.wall_s = report.wall_s;
  s.threads = options.threads;
  s.peak_rss_mb = report::peak_rss_mb();
  return s;
}

}  // namespace roiflow::pipeline
