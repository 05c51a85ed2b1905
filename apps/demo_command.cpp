// roiflow demo: the built-in synthetic scene tracked and scored (pipeline::run_demo); with
// --objects N the traffic scene's N vehicles (pipeline::run_mot_demo).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/demo.hpp"
#include "pipeline/mot_demo.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {
namespace {

int objects_demo(const pipeline::DemoOptions& d, int objects, bool frames_given) {
  pipeline::MotDemoOptions o;
  o.dir = d.dir, o.objects = objects, o.frames = frames_given ? d.frames : 300;
  o.threads = d.threads, o.progress = d.progress, o.cancel = d.cancel;
  const pipeline::MotDemoResult r = pipeline::run_mot_demo(o);
  if (r.cancelled) {
    std::cerr << "roiflow: error: interrupted\n";
    return 128 + pipeline::caught_signal();
  }
  std::cout << pipeline::mot_demo_text(r, o.threads);
  return 0;
}

int demo(pipeline::DemoOptions options, int objects, bool frames_given) {
  if (options.threads == 0) options.threads = pipeline::default_threads();
  options.cancel = pipeline::cancel_flag();
  pipeline::SignalScope signals;
  if (objects > 0) return objects_demo(options, objects, frames_given);
  const pipeline::DemoResult r = pipeline::run_demo(options);
  if (r.local.end == pipeline::RunEnd::Cancelled) {
    std::cerr << "roiflow: error: interrupted\n";
    return 128 + pipeline::caught_signal();
  }
  std::cout << pipeline::demo_text(r);
  return 0;
}

}  // namespace

void add_demo_command(CLI::App& app, int& exit_code) {
  static pipeline::DemoOptions cmd;  // threads 0: all
  static int objects = 0;
  cmd.threads = 0;
  cmd.progress = true;
  CLI::App* sub = app.add_subcommand(
      "demo",
      "Track a vehicle in a built-in synthetic video (no input needed) and print the error");
  sub->add_option("--dir", cmd.dir, "where the video, log and summary go")->capture_default_str();
  CLI::Option* frames =
      sub->add_option("--frames", cmd.frames, "length of the scene (with --objects: default 300)")
          ->check(CLI::Range(3, 100000))
          ->capture_default_str();
  sub->add_option("--objects", objects,
                  "track N vehicles of the synthetic traffic scene instead; writes mot.txt and "
                  "gt_mot.txt, prints MOTA and IDF1")
      ->check(CLI::Range(1, 256));
  sub->add_option("--threads", cmd.threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_flag("!--no-progress", cmd.progress, "no progress bar on the terminal");
  sub->callback([&exit_code, frames] { exit_code = demo(cmd, objects, frames->count() > 0); });
}

}  // namespace roiflow::cli
