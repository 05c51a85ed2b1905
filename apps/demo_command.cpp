// roiflow demo: the built-in synthetic scene tracked and scored (pipeline::run_demo).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/demo.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {
namespace {

struct DemoCommand {
  std::string dir = "out/demo";
  int frames = 150;
  int threads = 0;
  bool progress = true;
};

int run_demo(const DemoCommand& cmd) {
  pipeline::DemoOptions options;
  options.dir = cmd.dir;
  options.frames = cmd.frames;
  options.threads = cmd.threads > 0 ? cmd.threads : default_threads();
  options.progress = cmd.progress;
  options.cancel = cancel_flag();
  SignalScope signals;
  const pipeline::DemoResult r = pipeline::run_demo(options);
  if (r.local.end == pipeline::RunEnd::Cancelled) {
    std::cerr << "roiflow: error: interrupted\n";
    return 128 + caught_signal();
  }
  const eval::OtbScore& s = r.score;
  const double local_fps = r.local.tracker_fps;
  const double global_fps = r.global.tracker_fps;
  std::cout << "demo: synthetic fixed-camera scene " << size_text(r.scene.size) << ", "
            << r.scene.frames << " frames, the vehicle jumps " << fixed(r.scene.jump, 0)
            << " px at frame " << r.jump_frame + 1 << "\n";
  print_track_summary("  local mode", r.local, {});
  std::cout << "  error vs the scene's boxes: success AUC " << fixed(s.auc, 3) << ", precision@20 "
            << fixed(s.precision20, 3) << ", mean IoU " << fixed(s.mean_iou, 3)
            << ", mean centre error " << fixed(r.centre_error, 2)
            << " px after the first detection (frame " << r.first_detection << ")\n"
            << "  global mode (whole frame every frame): tracker " << fixed(global_fps, 1)
            << " fps; local mode is " << fixed(global_fps > 0 ? local_fps / global_fps : 0.0, 1)
            << "x faster\n"
            << "  wrote " << joined({r.video, r.log, r.summary, r.truth}) << "\n";
  return 0;
}

}  // namespace

void add_demo_command(CLI::App& app, int& exit_code) {
  static DemoCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "demo",
      "Track a vehicle in a built-in synthetic video (no input needed) and print the error");
  sub->add_option("--dir", cmd.dir, "where the video, log and summary go")->capture_default_str();
  sub->add_option("--frames", cmd.frames, "length of the scene")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  sub->add_option("--threads", cmd.threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_flag("!--no-progress", cmd.progress, "no progress bar on the terminal");
  sub->callback([&exit_code] { exit_code = run_demo(cmd); });
}

}  // namespace roiflow::cli
