// roiflow score: OTB metrics of a track log, or CLEAR-MOT and IDF1 (eval/score_text.hpp).
#include <iostream>

#include "cli_common.hpp"
#include "eval/score_text.hpp"

namespace roiflow::cli {

void add_score_command(CLI::App& app, int& /*exit_code*/) {
  static std::string track, truth, format = "table";
  static bool mot = false;
  CLI::App* sub =
      app.add_subcommand("score", "OTB one-pass metrics of a track log against ground-truth boxes");
  sub->add_option("TRACK", track, "track log written by roiflow track (CSV)")->required();
  sub->add_option("GROUNDTRUTH", truth, "one box x,y,w,h per frame (commas, tabs or spaces)")
      ->required();
  sub->add_option("--format", format, "output format")
      ->check(CLI::IsMember({"table", "json"}))
      ->capture_default_str();
  sub->add_flag("--mot", mot,
                "multi-object: TRACK and GROUNDTRUTH are MOTChallenge files (GROUNDTRUTH may be "
                "synthetic:N[:WxH]:OBJECTS); CLEAR-MOT and IDF1");
  sub->callback([] { std::cout << eval::score_text(track, truth, mot, format); });
}

}  // namespace roiflow::cli
