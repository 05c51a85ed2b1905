// roiflow demo: the built-in synthetic scene tracked and scored (pipeline::run_demo); with
// --objects N the traffic scene's N vehicles (pipeline::run_mot_demo).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/mot_demo.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {

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
  sub->callback([&exit_code, frames] {
    pipeline::DemoOptions o = cmd;
    if (o.threads == 0) o.threads = pipeline::default_threads();
    o.cancel = pipeline::cancel_flag();
    pipeline::SignalScope signals;
    const std::optional<std::string> text =
        pipeline::demo_command_text(o, objects, frames->count() > 0);
    if (text) std::cout << *text;
    exit_code = run_end(text ? pipeline::Ending{}
                             : pipeline::Ending{128 + pipeline::caught_signal(), "interrupted"});
  });
}

}  // namespace roiflow::cli
