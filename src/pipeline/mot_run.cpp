#include "pipeline/mot_run.hpp"

#include <cstdio>
#include <iostream>
#include <optional>

#include "core/atomic_write.hpp"
#include "report/annotate.hpp"
#include "report/progress.hpp"
#include "report/run_stats.hpp"
#include "stages/track_log_sink.hpp"
#include "stages/video_sink.hpp"

namespace roiflow::pipeline {
namespace {

double stage_ms(const nlohmann::ordered_json& stats, const char* stage) {
  const auto& stages = stats.at("stages");
  return stages.contains(stage) ? stages.at(stage).at("ms_total").get<double>() : 0.0;
}

report::ObjectsAnnotation annotation(const stages::MotFrame& f) {
  report::ObjectsAnnotation a;
  a.index = f.index;
  a.born = f.born;
  a.ended = f.ended;
  a.global = f.global;
  for (const stages::TrackedObject& o : f.objects)
    a.objects.push_back({o.id, o.box, o.velocity, o.lost, o.region});
  return a;
}

}  // namespace

std::string mot_row(long long index, const stages::TrackedObject& o, double conf) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%lld,%lld,%.2f,%.2f,%.2f,%.2f,%.3g,-1,-1,-1\n", index + 1,
                o.id, o.box.x + 1.0, o.box.y + 1.0, static_cast<double>(o.box.width),
                static_cast<double>(o.box.height), conf);
  return buffer;
}

MotRun track_objects(const FrameSource& source, cv::Size size, double fps,
                     const MotRunOptions& options) {
  options.params.validate();
  std::optional<stages::TrackLogWriter> log;
  if (!options.log.empty()) log.emplace(options.log);
  std::optional<stages::VideoSink> video;
  if (!options.video.empty()) video.emplace(options.video, fps, size);
  report::Progress progress(std::cerr, options.frame_hint,
                            options.progress && report::Progress::stderr_is_terminal());

  std::string mot_text;
  long long lost_records = 0, object_frames = 0, most_objects = 0;
  stages::MotFrame last;
  std::vector<MotSink> sinks;
  sinks.push_back({"log", [&](const MotTrackedFrame& f) {
                     long long found = 0;
                     for (const stages::TrackedObject& o : f.output->objects) {
                       if (o.lost) {
                         ++lost_records;
                       } else {
                         ++found;
                         if (!options.mot.empty()) mot_text += mot_row(f.output->index, o);
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
                       video->write(
                           report::annotate_objects(f.frame->picture(), annotation(*f.output)));
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
  if (!options.mot.empty()) write_text_atomically(options.mot, mot_text);

  const nlohmann::ordered_json s = stats.to_json(run.report.wall_s);
  double tracker_ms = 0;
  for (const char* stage : {"pyramid", "background", "global", "plan", "lk", "decide"})
    tracker_ms += stage_ms(s, stage);
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

}  // namespace roiflow::pipeline
