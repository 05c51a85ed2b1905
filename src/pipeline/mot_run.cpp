#include "pipeline/mot_run.hpp"

#include <fmt/format.h>

#include <iostream>
#include <optional>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/mot.hpp"
#include "eval/otb_score.hpp"
#include "report/annotate.hpp"
#include "report/progress.hpp"
#include "report/run_stats.hpp"
#include "video/track_log_sink.hpp"
#include "video/video_sink.hpp"

namespace roiflow::pipeline {
namespace {

report::ObjectsAnnotation objects_annotation(const tracking::MotFrame& f) {
  report::ObjectsAnnotation a;
  a.index = f.index;
  a.born = f.born;
  a.ended = f.ended;
  a.global = f.global;
  for (const tracking::MotObject& o : f.objects)
    a.objects.push_back({o.id, o.box, o.velocity, o.lost, o.region});
  return a;
}

}  // namespace

eval::MotBox mot_box(long long index, const tracking::MotObject& o) {
  eval::MotBox b;
  b.frame = static_cast<int>(index + 1);
  b.id = static_cast<int>(o.id);
  b.box = cv::Rect2d(o.box.x + 1.0, o.box.y + 1.0, o.box.width, o.box.height);
  b.conf = 1;
  return b;
}

MotRun track_objects(const FrameSource& source, cv::Size size, double fps,
                     const MotRunOptions& options) {
  options.params.validate();
  std::optional<video::TrackLogWriter> log;
  if (!options.log.empty()) log.emplace(options.log);
  std::optional<video::VideoSink> video;
  if (!options.video.empty()) video.emplace(options.video, fps, size);
  report::Progress progress(std::cerr, options.frame_hint,
                            options.progress && report::Progress::stderr_is_terminal());

  std::vector<eval::MotBox> mot_boxes;
  long long lost_records = 0, object_frames = 0, most_objects = 0;
  tracking::MotFrame last;
  std::vector<MotSink> sinks;
  sinks.push_back({"log", [&](const MotTrackedFrame& f) {
                     long long found = 0;
                     for (const tracking::MotObject& o : f.output->objects) {
                       if (o.lost) {
                         ++lost_records;
                       } else {
                         ++found;
                         if (!options.mot.empty()) mot_boxes.push_back(mot_box(f.output->index, o));
                       }
                       if (log) {
                         eval::TrackRecord r;
                         r.frame = f.output->index + 1;
                         r.id = o.id;
                         r.box = o.box;
                         r.velocity = o.velocity;
                         r.mode = eval::TrackRecord::Mode::Local;
                         r.lost = o.lost;
                         r.ms = f.output->ms;
                         log->write(r);
                       }
                     }
                     object_frames += found;
                     most_objects = std::max(most_objects, found);
                     last = *f.output;
                     if (options.on_frame) options.on_frame(f);
                   }});
  if (video) {
    sinks.push_back({"video", [&](const MotTrackedFrame& f) {
                       video->write(report::annotate_objects(f.frame->picture(),
                                                             objects_annotation(*f.output)));
                     }});
  }
  sinks.push_back({"progress", [&](const MotTrackedFrame& f) { progress.update(f.seq + 1); }});

  report::RunStats stats;
  GraphOptions graph;
  graph.threads = options.threads;
  graph.max_in_flight = options.in_flight;
  graph.cancel = options.cancel;
  graph.stats = &stats;
  MotRun run;
  run.report = run_mot(source, options.params, sinks, graph);
  progress.finish();
  if (log) log->close();
  if (video) video->close();
  if (!options.mot.empty()) eval::write_mot(options.mot, mot_boxes);

  const nlohmann::ordered_json s = stats.to_json(run.report.wall_s);
  double tracker_ms = 0;
  for (const char* stage :
       {"pyramid", "start_flow", "background", "global", "split", "plan", "lk", "decide"})
    tracker_ms += report::stage_ms_total(s, stage);
  const double frames = static_cast<double>(run.report.frames);
  run.summary = {{"mode", "objects"},
                 {"frames", run.report.frames},
                 {"objects_born", last.born},
                 {"objects_ended", last.ended},
                 {"global_activations", last.global_activations},
                 {"object_frames", object_frames},
                 {"most_objects", most_objects},
                 {"lost_frames", lost_records},
                 {"fps", run.report.wall_s > 0 ? frames / run.report.wall_s : 0.0},
                 {"tracker_fps", tracker_ms > 0 ? frames / (tracker_ms / 1000.0) : 0.0},
                 {"tracker_ms_per_frame", frames > 0 ? tracker_ms / frames : 0.0},
                 {"wall_s", run.report.wall_s},
                 {"threads", options.threads},
                 {"max_in_flight", run.report.max_in_flight},
                 {"peak_rss_mb", report::peak_rss_mb()},
                 {"stages", s.at("stages")}};
  return run;
}

std::vector<tracking::KnownTarget> known_targets(const std::vector<std::string>& boxes,
                                                 const std::string& file) {
  std::vector<tracking::KnownTarget> known;
  if (!file.empty()) {
    if (!boxes.empty()) throw UsageError("--init-file: give the targets either there or by --init");
    try {
      return tracking::read_known_targets(file);
    } catch (const Error& e) {
      throw UsageError(std::string("--init-file: ") + e.what());
    }
  }
  for (const std::string& text : boxes) {
    try {
      known.push_back({static_cast<long long>(known.size()) + 1, eval::parse_box(text)});
    } catch (const Error& e) {
      throw UsageError(std::string("--init: ") + e.what());
    }
  }
  return known;
}

MotRun track_objects_video(video::VideoSource& source, const MotRunOptions& options) {
  const cv::Rect2f frame(0.f, 0.f, static_cast<float>(source.size().width),
                         static_cast<float>(source.size().height));
  for (const tracking::KnownTarget& k : options.params.known) {
    const cv::Rect2f inside = k.box & frame;
    if (inside.width < 2 || inside.height < 2)
      throw UsageError(
          fmt::format("target {} lies outside the {} frame", k.id, size_text(source.size())));
  }
  MotRunOptions o = options;
  o.frame_hint = source.frame_count_hint();
  MotRun run = track_objects([&] { return source.next(); }, source.size(), source.fps(), o);
  const video::SourceStatus& status = source.status();
  run.end = run.report.cancelled                                   ? RunEnd::Cancelled
            : status.state == video::SourceStatus::State::kStopped ? RunEnd::InputStopped
                                                                   : RunEnd::Complete;
  const Ending end = ending(run.end, run.report.frames, status.message);
  run.summary["input"] = source.description();
  run.summary["status"] = end.message.empty() ? status.message : end.message;
  return run;
}

std::string objects_summary_text(const std::string& what, const nlohmann::ordered_json& s) {
  return fmt::format(
      "{}: {} frames in {:.2f} s, {:.1f} fps overall, tracker {:.1f} fps ({:.3f} ms/frame, decode "
      "excluded), every moving object\n  global activations {}, lost records {}, {} threads\n"
      "  objects born {}, ended {}, at most {} at once\n",
      what, s.at("frames").get<long long>(), s.at("wall_s").get<double>(),
      s.at("fps").get<double>(), s.at("tracker_fps").get<double>(),
      s.at("tracker_ms_per_frame").get<double>(), s.at("global_activations").get<long long>(),
      s.at("lost_frames").get<long long>(), s.at("threads").get<int>(),
      s.at("objects_born").get<long long>(), s.at("objects_ended").get<long long>(),
      s.at("most_objects").get<long long>());
}

}  // namespace roiflow::pipeline
