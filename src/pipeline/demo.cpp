#include "pipeline/demo.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "core/atomic_write.hpp"
#include "core/text.hpp"
#include "pipeline/run_json.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;

FrameSource scene_source(const eval::TrackingScene& scene) {
  return [&scene, next = 0]() mutable -> std::optional<video::Frame> {
    if (next >= scene.frames()) return std::nullopt;
    video::Frame f;
    f.index = next;
    f.timestamp_s = next / 25.0;
    f.image = scene.render(next);
    cv::cvtColor(f.image, f.gray, cv::COLOR_BGR2GRAY);
    ++next;
    return f;
  };
}

}  // namespace

DemoResult run_demo(const DemoOptions& options) {
  fs::create_directories(options.dir);
  DemoResult r;
  r.scene.frames = options.frames;
  const eval::TrackingScene scene(r.scene);
  r.jump_frame = scene.jump_frame();
  const fs::path dir = options.dir;
  r.video = (dir / "demo.mp4").string();
  r.log = (dir / "track.csv").string();
  r.summary = (dir / "summary.json").string();
  r.truth = (dir / "groundtruth.txt").string();

  std::vector<cv::Rect2f> truth;
  std::string truth_text;
  for (int i = 0; i < scene.frames(); ++i) {
    const cv::Rect2f& b = truth.emplace_back(scene.box(i));
    truth_text += fixed(b.x, 2) + "," + fixed(b.y, 2) + "," + fixed(b.width, 2) + "," +
                  fixed(b.height, 2) + "\n";
  }
  const StreamInfo info{scene.size(), 25.0, scene.frames(), ""};
  TrackRunOptions run;  // paper defaults, no init: the global treatment finds the vehicle
  run.threads = options.threads;
  run.log = r.log;
  run.video = r.video;
  run.progress = options.progress;
  run.keep_records = true;
  run.cancel = options.cancel;
  r.local = run_track_stream(scene_source(scene), info, run);
  if (r.local.end == RunEnd::Cancelled) return r;
  run.tracker.mode = tracking::TrackMode::Global;
  run.log.clear();
  run.video.clear();
  run.progress = false;
  run.keep_records = false;
  r.global = run_track_stream(scene_source(scene), info, run);

  std::vector<cv::Rect2f> boxes;
  for (const eval::TrackRecord& record : r.local.records)
    boxes.push_back(record.box);
  r.score = eval::score(boxes, truth);
  int found_at = -1;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (found_at < 0 && boxes[i].area() > 0) found_at = static_cast<int>(i);
    if (found_at >= 0) r.centre_error += eval::center_error(boxes[i], truth[i]);
  }
  const long long tracked = found_at < 0 ? 0 : static_cast<long long>(boxes.size()) - found_at;
  if (tracked > 0) r.centre_error /= static_cast<double>(tracked);
  r.first_detection = found_at + 1;

  nlohmann::ordered_json doc = to_json(r.local);
  doc["input"] = "synthetic scene " + size_text(scene.size()) + ", " +
                 std::to_string(scene.frames()) + " frames";
  doc["score"] = {{"auc", r.score.auc},
                  {"precision20", r.score.precision20},
                  {"mean_iou", r.score.mean_iou},
                  {"mean_center_error", r.centre_error},
                  {"first_detection_frame", r.first_detection}};
  doc["global_mode"] = {{"tracker_fps", r.global.tracker_fps}, {"fps", r.global.fps}};
  write_text_atomically(r.summary, doc.dump(2) + "\n");
  write_text_atomically(r.truth, truth_text);
  return r;
}

std::string demo_text(const DemoResult& r) {
  const double speedup = r.global.tracker_fps > 0 ? r.local.tracker_fps / r.global.tracker_fps : 0;
  return fmt::format(
             "demo: synthetic fixed-camera scene {}, {} frames, the vehicle jumps {:.0f} px at "
             "frame {}\n",
             size_text(r.scene.size), r.scene.frames, r.scene.jump, r.jump_frame + 1) +
         summary_text("  local mode", r.local) +
         fmt::format(
             "  error vs the scene's boxes: success AUC {:.3f}, precision@20 {:.3f}, mean IoU "
             "{:.3f}, mean centre error {:.2f} px after the first detection (frame {})\n"
             "  global mode (whole frame every frame): tracker {:.1f} fps; local mode is {:.1f}x "
             "faster\n  wrote {}, {}, {}, {}\n",
             r.score.auc, r.score.precision20, r.score.mean_iou, r.centre_error, r.first_detection,
             r.global.tracker_fps, speedup, r.video, r.log, r.summary, r.truth);
}

}  // namespace roiflow::pipeline
