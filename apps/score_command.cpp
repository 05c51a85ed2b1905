// roiflow score: OTB one-pass metrics of a track log against ground-truth boxes.
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "eval/otb_score.hpp"
#include "eval/score_text.hpp"

namespace roiflow::cli {
namespace {

struct ScoreCommand {
  std::string track;
  std::string ground_truth;
  std::string format = "table";
  bool mot = false;
};

void run_score(const ScoreCommand& cmd) {
  if (cmd.mot) {
    const auto truth = eval::read_mot_truth(cmd.ground_truth);  // read first
    const eval::MotScore s = eval::score_mot(eval::read_mot(cmd.track, "tracker output"), truth);
    std::cout << (cmd.format == "json" ? mot_score_json(s).dump(2) + "\n" : mot_score_table(s));
    return;
  }
  const std::vector<cv::Rect2f> track = eval::read_track_boxes(cmd.track);
  const std::vector<cv::Rect2f> truth = eval::read_ground_truth(cmd.ground_truth);
  const eval::OtbScore s = eval::score(track, truth);

  if (cmd.format == "json") {
    std::cout << nlohmann::ordered_json({{"auc", s.auc},
                                         {"precision20", s.precision20},
                                         {"mean_iou", s.mean_iou},
                                         {"frames", s.frames}})
                     .dump(2)
              << "\n";
  } else {
    std::cout << eval::score_table(s, track.size(), truth.size());
  }
}

}  // namespace

void add_score_command(CLI::App& app, int& /*exit_code*/) {
  static ScoreCommand cmd;
  CLI::App* sub =
      app.add_subcommand("score", "OTB one-pass metrics of a track log against ground-truth boxes");
  sub->add_option("TRACK", cmd.track, "track log written by roiflow track (CSV)")
      ->type_name("CSV")
      ->required();
  sub->add_option("GROUNDTRUTH", cmd.ground_truth,
                  "one box x,y,w,h per frame, separated by commas, tabs or spaces")
      ->type_name("TXT")
      ->required();
  sub->add_option("--format", cmd.format, "output format")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"table", "json"}))
      ->capture_default_str();
  sub->add_flag("--mot", cmd.mot,
                "multi-object: TRACK and GROUNDTRUTH are MOTChallenge files (GROUNDTRUTH may be "
                "synthetic:N[:WxH]:OBJECTS); CLEAR-MOT and IDF1");
  sub->callback([] { run_score(cmd); });
}

}  // namespace roiflow::cli
