#include "pipeline/mot_demo.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "eval/traffic_scene.hpp"
#include "pipeline/mot_run.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;

void prepare_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  if (fs::exists(dir, ec)) throw Error("demo: '" + dir + "' exists and is not a directory");
  const fs::path parent = fs::path(dir).lexically_normal().parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error("demo: directory '" + parent.string() + "' of '" + dir + "' does not exist");
  }
  if (!fs::create_directory(dir, ec) && !fs::is_directory(dir)) {
    throw Error("demo: cannot create directory '" + dir + "': " + ec.message());
  }
}

}  // namespace

MotDemoResult run_mot_demo(const MotDemoOptions& options) {
  eval::TrafficSceneParams scene_params;
  scene_params.size = options.size;
  scene_params.frames = options.frames;
  scene_params.objects = options.objects;
  const eval::TrafficScene scene(scene_params);  // validates
  prepare_dir(options.dir);
  constexpr double kFps = 25.0;
  const auto file = [&](const char* name) { return (fs::path(options.dir) / name).string(); };

  MotDemoResult result;
  result.mot = file("mot.txt");
  result.ground_truth = file("gt_mot.txt");
  result.log = file("track.csv");
  result.video = options.video ? file("demo.mp4") : "";
  result.summary_path = file("summary.json");

  long long next = 0;
  const FrameSource source = [&]() -> std::optional<video::Frame> {
    if (next >= scene.frames()) return std::nullopt;
    video::Frame f;
    f.index = next;
    f.timestamp_s = static_cast<double>(next) / kFps;
    f.image = scene.render(next);
    cv::cvtColor(f.image, f.gray, cv::COLOR_BGR2GRAY);
    ++next;
    return f;
  };
  MotRunOptions run_options;
  run_options.mot = result.mot;
  run_options.log = result.log;
  run_options.video = result.video;
  run_options.threads = options.threads;
  run_options.progress = options.progress;
  run_options.frame_hint = scene.frames();
  run_options.cancel = options.cancel;
  const MotRun run = track_objects(source, scene.size(), kFps, run_options);
  if (run.report.cancelled) {
    result.cancelled = true;
    return result;
  }
  const std::vector<eval::MotBox> truth = scene.ground_truth();
  eval::write_mot(result.ground_truth, truth);
  // Scored from the two files, as `roiflow score --mot` reads them (2-decimal boxes: an IoU at
  // 0.5 may fall either side of it with the exact boxes).
  result.score = eval::score_mot(eval::read_mot(result.mot, "tracker output"),
                                 eval::read_mot(result.ground_truth, "ground truth"));

  const eval::MotScore& s = result.score;
  result.summary = run.summary;
  result.summary["input"] = "synthetic traffic " + std::to_string(scene.size().width) + "x" +
                            std::to_string(scene.size().height) + ", " +
                            std::to_string(scene.frames()) + " frames, " +
                            std::to_string(scene.objects()) + " vehicles";
  result.summary["mota"] = s.mota;
  result.summary["idf1"] = s.idf1;
  result.summary["motp"] = s.motp;
  result.summary["id_switches"] = s.id_switches;
  result.summary["fp"] = s.fp;
  result.summary["fn"] = s.fn;
  result.summary["gt_objects"] = s.objects;
  write_text_atomically(result.summary_path, result.summary.dump(2) + "\n");
  return result;
}

std::string mot_demo_text(const MotDemoResult& r, int threads) {
  const eval::MotScore& s = r.score;
  const nlohmann::ordered_json& j = r.summary;
  return fmt::format(
      "demo: {} (crossing, entering and leaving, changing speed)\n"
      "  tracked every moving object: {} frames, {:.1f} fps, tracker {:.1f} fps, {} objects born, "
      "{} ended, {} threads\n"
      "  against the scene's exact boxes: MOTA {:.3f}, IDF1 {:.3f}, MOTP {:.3f}, ID switches {}, "
      "FP {}, FN {} ({} boxes of {} objects)\n"
      "  wrote {}, {}, {}, {}, {}\n",
      j.at("input").get<std::string>(), j.at("frames").get<long long>(), j.at("fps").get<double>(),
      j.at("tracker_fps").get<double>(), j.at("objects_born").get<long long>(),
      j.at("objects_ended").get<long long>(), threads, s.mota, s.idf1, s.motp, s.id_switches, s.fp,
      s.fn, s.gt_boxes, s.objects, r.mot, r.ground_truth, r.log, r.video, r.summary_path);
}

std::optional<std::string> demo_command_text(const DemoOptions& options, int objects,
                                             bool frames_given) {
  if (objects == 0) {
    const DemoResult r = run_demo(options);
    if (r.local.end == RunEnd::Cancelled) return std::nullopt;
    return demo_text(r);
  }
  MotDemoOptions o;
  o.dir = options.dir;
  o.objects = objects;
  o.frames = frames_given ? options.frames : 300;
  o.threads = options.threads;
  o.progress = options.progress;
  o.cancel = options.cancel;
  const MotDemoResult r = run_mot_demo(o);
  if (r.cancelled) return std::nullopt;
  return mot_demo_text(r, o.threads);
}

}  // namespace roiflow::pipeline
