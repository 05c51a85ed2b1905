// roiflow score --mot PRED GT: CLEAR-MOT and IDF1 of a MOTChallenge tracker output against
// MOTChallenge ground truth (the scoring is eval::score_mot, src/eval/mot.hpp).
//
//   roiflow score --mot out/mot.txt ../shared/data/mot/PETS09-S2L1/gt/gt.txt --format json
//   -> {"mota": ..., "motp": ..., "idf1": ..., "id_switches": ..., "fp": ..., "fn": ...,
//       "frames": ..., "objects": ...}
//   roiflow score --mot out/mot.txt synthetic:300:640x480:16   # the traffic scene's exact boxes
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_common.hpp"
#include "core/error.hpp"
#include "eval/mot.hpp"
#include "eval/synthetic_input.hpp"
#include "eval/traffic_scene.hpp"

namespace roiflow::cli {

void print_mot_score(const std::string& pred, const std::string& gt, const std::string& format) {
  std::vector<eval::MotBox> truth;
  std::error_code ec;
  if (eval::is_synthetic_input(gt) && !std::filesystem::exists(gt, ec)) {
    // A synthetic traffic input as ground truth: its exact boxes (as VideoSource reads inputs).
    const eval::SyntheticInput spec = eval::parse_synthetic_input(gt);
    if (spec.objects == 0) {
      throw Error("ground truth '" + gt +
                  "': only synthetic inputs with OBJECTS (synthetic:N[:WxH]:OBJECTS) have "
                  "multi-object ground truth");
    }
    truth = eval::TrafficScene(eval::traffic_params(spec)).ground_truth();
  } else {
    truth = eval::read_mot(gt, "ground truth");
  }
  const std::vector<eval::MotBox> output = eval::read_mot(pred, "tracker output");
  const eval::MotScore s = eval::score_mot(output, truth);
  if (format == "json") {
    const nlohmann::ordered_json doc = {
        {"mota", s.mota}, {"motp", s.motp}, {"idf1", s.idf1},     {"id_switches", s.id_switches},
        {"fp", s.fp},     {"fn", s.fn},     {"frames", s.frames}, {"objects", s.objects}};
    std::cout << doc.dump(2) << "\n";
    return;
  }
  std::cout << "MOTA           " << fixed(s.mota, 4) << "\n"
            << "MOTP (IoU)     " << fixed(s.motp, 4) << "\n"
            << "IDF1           " << fixed(s.idf1, 4) << "  (IDP " << fixed(s.idp, 4) << ", IDR "
            << fixed(s.idr, 4) << ")\n"
            << "ID switches    " << s.id_switches << "\n"
            << "FP             " << s.fp << "\n"
            << "FN             " << s.fn << "\n"
            << "matches        " << s.matches << " of " << s.gt_boxes << " ground-truth boxes, "
            << s.pred_boxes << " tracker boxes\n"
            << "frames         " << s.frames << "\n"
            << "objects        " << s.objects << " (tracker ids " << s.tracks << ")\n";
}

}  // namespace roiflow::cli
