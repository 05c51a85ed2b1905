// The demo: eval::TrackingScene's synthetic fixed-camera video (a vehicle that jumps once,
// further than a local region can follow) tracked without --init in local mode, then in global
// mode for the speed-up, and scored against the scene's exact boxes. run_demo writes demo.mp4
// (annotated), track.csv, summary.json and groundtruth.txt into the folder it is given.
//
//   roiflow::pipeline::DemoOptions options;
//   options.dir = "out/demo";
//   const roiflow::pipeline::DemoResult r = roiflow::pipeline::run_demo(options);
//   std::cout << roiflow::pipeline::demo_text(r);  // or r.score.auc, r.local.tracker_fps, ...
#pragma once

#include <atomic>
#include <string>

#include "eval/otb_score.hpp"
#include "eval/tracking_scene.hpp"
#include "pipeline/run.hpp"

namespace roiflow::pipeline {

struct DemoOptions {
  std::string dir = "out/demo";  // created if missing
  int frames = 150;
  int threads = 1;
  bool progress = false;
  const std::atomic<bool>* cancel = nullptr;
};

struct DemoResult {
  eval::TrackingSceneParams scene;
  int jump_frame = 0;
  TrackSummary local, global;              // global is empty when local was cancelled
  eval::OtbScore score;                    // of the local run
  double centre_error = 0;                 // mean, pixels, from the first detection on
  int first_detection = 0;                 // 1-based frame; 0 = never
  std::string video, log, summary, truth;  // the files written
};

DemoResult run_demo(const DemoOptions& options);
// What `roiflow demo` prints: the scene, the local run, its error, the speed-up, the files.
std::string demo_text(const DemoResult& r);

}  // namespace roiflow::pipeline
