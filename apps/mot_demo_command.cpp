// roiflow demo --objects N: the multi-object demo (pipeline::run_mot_demo,
// src/pipeline/mot_demo.hpp) and what it prints.
//
//   roiflow demo --objects 16 --dir out/demo
//   -> out/demo/mot.txt, gt_mot.txt, track.csv, demo.mp4, summary.json (with mota and idf1)
#include <atomic>
#include <csignal>
#include <iostream>
#include <string>

#include "cli_common.hpp"
#include "pipeline/mot_demo.hpp"

namespace roiflow::cli {
namespace {

// SIGINT / SIGTERM stop the source; frames in flight finish and the outputs are closed.
std::atomic<bool> g_demo_cancel{false};
std::atomic<int> g_demo_signal{0};

extern "C" void on_demo_signal(int signal) {
  g_demo_signal.store(signal);
  g_demo_cancel.store(true);
}

}  // namespace

int run_objects_demo(const std::string& dir, int objects, int frames, int threads, bool progress) {
  pipeline::MotDemoOptions o;
  o.dir = dir;
  o.objects = objects;
  o.frames = frames;
  o.threads = threads;
  o.progress = progress;
  o.cancel = &g_demo_cancel;
  void (*previous_int)(int) = std::signal(SIGINT, on_demo_signal);
  void (*previous_term)(int) = std::signal(SIGTERM, on_demo_signal);
  pipeline::MotDemoResult r;
  try {
    r = pipeline::run_mot_demo(o);
  } catch (...) {
    std::signal(SIGINT, previous_int);
    std::signal(SIGTERM, previous_term);
    throw;
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (r.cancelled) {
    std::cerr << "roiflow: error: interrupted\n";
    return 128 + g_demo_signal.load();
  }
  const eval::MotScore& s = r.score;
  const nlohmann::ordered_json& j = r.summary;
  std::cout << "demo: " << j.at("input").get<std::string>()
            << " (crossing, entering and leaving, changing speed)\n"
            << "  tracked every moving object: " << j.at("frames").get<long long>() << " frames, "
            << fixed(j.at("fps").get<double>(), 1) << " fps, tracker "
            << fixed(j.at("tracker_fps").get<double>(), 1) << " fps, "
            << j.at("objects_born").get<long long>() << " objects born, "
            << j.at("objects_ended").get<long long>() << " ended, " << threads << " threads\n"
            << "  against the scene's exact boxes: MOTA " << fixed(s.mota, 3) << ", IDF1 "
            << fixed(s.idf1, 3) << ", MOTP " << fixed(s.motp, 3) << ", ID switches "
            << s.id_switches << ", FP " << s.fp << ", FN " << s.fn << " (" << s.gt_boxes
            << " boxes of " << s.objects << " objects)\n"
            << "  wrote " << r.mot << ", " << r.ground_truth << ", " << r.log << ", " << r.video
            << ", " << r.summary_path << "\n";
  return 0;
}

}  // namespace roiflow::cli
