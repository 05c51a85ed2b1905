// roiflow score: OTB one-pass metrics of a track log against ground-truth boxes.
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "eval/otb_score.hpp"
#include "eval/track_log.hpp"

namespace roiflow::cli {
namespace {

struct ScoreCommand {
  std::string track;
  std::string ground_truth;
  std::string format = "table";
};

void run_score(const ScoreCommand& cmd) {
  const std::vector<eval::TrackRecord> records = eval::read_track_csv(cmd.track);
  std::vector<cv::Rect2f> track;
  try {
    track = eval::track_boxes(records);
  } catch (const Error& e) {
    // track_boxes knows records, not the file they came from.
    throw Error("track log '" + cmd.track + "': " + e.what());
  }
  const std::vector<cv::Rect2f> truth = eval::read_ground_truth(cmd.ground_truth);
  const eval::OtbScore s = eval::score(track, truth);

  if (cmd.format == "json") {
    const nlohmann::ordered_json doc = {{"auc", s.auc},
                                        {"precision20", s.precision20},
                                        {"mean_iou", s.mean_iou},
                                        {"frames", s.frames}};
    std::cout << doc.dump(2) << "\n";
    return;
  }
  // The lengths are shown because a shorter track (--max-frames) scores only its prefix.
  std::cout << "success AUC    " << fixed(s.auc, 4) << "\n"
            << "precision@20   " << fixed(s.precision20, 4) << "\n"
            << "mean IoU       " << fixed(s.mean_iou, 4) << "\n"
            << "frames         " << s.frames << " (track " << track.size() << ", ground truth "
            << truth.size() << ")\n";
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
  sub->callback([] { run_score(cmd); });
}

}  // namespace roiflow::cli
