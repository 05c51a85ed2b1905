// The multi-object demo: the synthetic traffic scene (eval::TrafficScene) tracked by
// pipeline::track_objects, scored against its exact boxes with CLEAR-MOT and IDF1.
//
//   using namespace roiflow;
//   pipeline::MotDemoOptions o;
//   o.dir = "out/demo";
//   o.objects = 16;
//   const pipeline::MotDemoResult r = pipeline::run_mot_demo(o);
//   std::cout << r.score.mota << " " << r.score.idf1 << "\n";
//
// Writes into `dir` (created if missing, its parent must exist): mot.txt (the tracker's
// MOTChallenge output), gt_mot.txt (the scene's ground truth, same format), track.csv (the track
// log with ids), demo.mp4 (annotated, unless `video` is false) and summary.json: the run's
// summary (frames, fps, tracker_fps, objects_born, ...) with "mota", "idf1", "motp",
// "id_switches", "fp", "fn" and "input" added. Every file is the one its figures were computed
// from: summary's mota and idf1 are `roiflow score --mot mot.txt gt_mot.txt` of the files.
#pragma once

#include <atomic>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "eval/mot.hpp"
#include "pipeline/demo.hpp"

namespace roiflow::pipeline {

struct MotDemoOptions {
  std::string dir = "out/demo";
  int objects = 16;        // vehicles, 1..256
  long long frames = 300;  // >= 1
  cv::Size size{640, 480};
  int threads = 1;        // worker threads, 1..kMaxThreads
  bool video = true;      // write demo.mp4
  bool progress = false;  // progress bar on stderr (a terminal only)
  const std::atomic<bool>* cancel = nullptr;
};

struct MotDemoResult {
  eval::MotScore score;            // of mot.txt against gt_mot.txt
  nlohmann::ordered_json summary;  // what summary.json holds
  bool cancelled = false;          // *cancel became true: nothing was scored or written
  std::string mot, ground_truth, log, video, summary_path;  // the files written
};

// Throws roiflow::Error for bad options or an output that cannot be written.
MotDemoResult run_mot_demo(const MotDemoOptions& options);
// What `roiflow demo --objects N` prints: the run, the score and the files, lines ending in '\n'.
std::string mot_demo_text(const MotDemoResult& r, int threads);

// `roiflow demo`: run_demo, or with `objects` > 0 run_mot_demo on that many vehicles (the
// options' frames when `frames_given`, else 300), with the options' threads, progress and
// cancel flag. Returns what the command prints; nothing when the cancel flag cut the run short.
std::optional<std::string> demo_command_text(const DemoOptions& options, int objects,
                                             bool frames_given);

}  // namespace roiflow::pipeline
