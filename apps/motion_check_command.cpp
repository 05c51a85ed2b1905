// roiflow motion-check VIDEO LOG: found boxes without moving pixels or collapsed (exit 1 when a run
// exceeds --max-run frames; pipeline/motion_check.hpp).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/motion_check.hpp"

namespace roiflow::cli {

void add_motion_check_command(CLI::App& app, int& exit_code) {
  static struct {
    std::string video, log, format = "table";
    pipeline::MotionCheckParams params;
  } cmd;
  CLI::App* sub = app.add_subcommand(
      "motion-check",
      "Check a track log against the video's moving pixels: no object reported found on empty "
      "background or collapsed for more than --max-run frames");
  sub->add_option("VIDEO", cmd.video, "the video the log was made from")->required();
  sub->add_option("LOG", cmd.log, "track log (.csv, with or without the id column)")->required();
  sub->add_option("--max-run", cmd.params.max_run, "longest run allowed, frames")
      ->check(CLI::Range(0LL, 1000000LL))
      ->capture_default_str();
  sub->add_option("--min-side", cmd.params.min_side, "a box narrower than this has collapsed")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--format", cmd.format, "table or json")
      ->check(CLI::IsMember({"table", "json"}))
      ->capture_default_str();
  sub->callback([&exit_code] {
    const std::vector<eval::TrackRecord> log = eval::read_track_csv(cmd.log);
    video::VideoSource video(cmd.video);
    const pipeline::MotionCheck c =
        pipeline::check_motion([&] { return video.next(); }, log, cmd.params);
    std::cout << (cmd.format == "json" ? pipeline::to_json(c).dump(2) + "\n"
                                       : pipeline::motion_check_text(c, cmd.params.max_run));
    exit_code = c.violations.empty() ? 0 : 1;
  });
}

}  // namespace roiflow::cli
