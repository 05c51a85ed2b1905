// What `roiflow score` prints: for a single-object track log against OTB ground truth, AUC,
// precision@20 and mean IoU; for a multi-object track (score --mot), CLEAR-MOT and IDF1. Each
// as a table for people, or the headline figures as JSON.
//
//   const auto s = roiflow::eval::score_mot(roiflow::eval::read_mot("mot.txt", "tracker output"),
//                                           roiflow::eval::read_mot("gt.txt", "ground truth"));
//   std::cout << roiflow::eval::mot_score_table(s);
//   std::cout << roiflow::eval::score_text("track.csv", "groundtruth_rect.txt", false, "json");
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "eval/mot.hpp"

namespace roiflow::eval {

// The ground truth `roiflow score --mot` scores against: a MOTChallenge file, or the exact boxes
// of a synthetic traffic input (synthetic:N[:WxH]:OBJECTS, when no such file exists).
std::vector<MotBox> read_mot_truth(const std::string& gt);
// MOTA, MOTP, IDF1 (IDP, IDR) to 4 decimals, ID switches, FP, FN, matches, frames, objects.
std::string mot_score_table(const MotScore& s);
// {"mota", "motp", "idf1", "id_switches", "fp", "fn", "frames", "objects"}.
nlohmann::ordered_json mot_score_json(const MotScore& s);

// `roiflow score TRACK GT [--mot] [--format table|json]`: the files read (ground truth first),
// scored and formatted. Throws roiflow::Error naming the file for unreadable input.
std::string score_text(const std::string& track, const std::string& ground_truth, bool mot,
                       const std::string& format);

}  // namespace roiflow::eval
