// roiflow demo: the built-in synthetic scene tracked and scored (pipeline::run_demo).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/demo.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {
namespace {

int demo(pipeline::DemoOptions options) {
  if (options.threads == 0) options.threads = pipeline::default_threads();
  options.cancel = pipeline::cancel_flag();
  pipeline::SignalScope signals;
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
  cmd.threads = 0;
  cmd.progress = true;
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
  sub->callback([&exit_code] { exit_code = demo(cmd); });
}

}  // namespace roiflow::cli
