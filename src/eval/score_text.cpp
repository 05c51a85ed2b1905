#include "eval/score_text.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "core/error.hpp"
#include "eval/otb_score.hpp"
#include "eval/synthetic_input.hpp"
#include "eval/traffic_scene.hpp"

namespace roiflow::eval {

std::vector<MotBox> read_mot_truth(const std::string& gt) {
  std::error_code ec;
  if (!is_synthetic_input(gt) || std::filesystem::exists(gt, ec))
    return read_mot(gt, "ground truth");
  // A synthetic traffic input as ground truth: its exact boxes (as VideoSource reads inputs).
  const SyntheticInput spec = parse_synthetic_input(gt);
  if (spec.objects == 0) {
    throw Error("ground truth '" + gt +
                "': only synthetic inputs with OBJECTS (synthetic:N[:WxH]:OBJECTS) have "
                "multi-object ground truth");
  }
  return TrafficScene(traffic_params(spec)).ground_truth();
}

std::string mot_score_table(const MotScore& s) {
  return fmt::format(
      "MOTA           {:.4f}\nMOTP (IoU)     {:.4f}\nIDF1           {:.4f}  (IDP {:.4f}, IDR "
      "{:.4f})\nID switches    {}\nFP             {}\nFN             {}\nmatches        {} of {} "
      "ground-truth boxes, {} tracker boxes\nframes         {}\nobjects        {} (tracker ids "
      "{})\n",
      s.mota, s.motp, s.idf1, s.idp, s.idr, s.id_switches, s.fp, s.fn, s.matches, s.gt_boxes,
      s.pred_boxes, s.frames, s.objects, s.tracks);
}

nlohmann::ordered_json mot_score_json(const MotScore& s) {
  return {{"mota", s.mota}, {"motp", s.motp}, {"idf1", s.idf1},     {"id_switches", s.id_switches},
          {"fp", s.fp},     {"fn", s.fn},     {"frames", s.frames}, {"objects", s.objects}};
}

std::string score_text(const std::string& track, const std::string& ground_truth, bool mot,
                       const std::string& format) {
  const bool json = format == "json";
  if (mot) {
    const std::vector<MotBox> truth = read_mot_truth(ground_truth);  // read first
    const MotScore s = score_mot(read_mot(track, "tracker output"), truth);
    return json ? mot_score_json(s).dump(2) + "\n" : mot_score_table(s);
  }
  const std::vector<cv::Rect2f> boxes = read_track_boxes(track);
  const std::vector<cv::Rect2f> truth = read_ground_truth(ground_truth);
  const OtbScore s = score(boxes, truth);
  if (!json) return score_table(s, boxes.size(), truth.size());
  return nlohmann::ordered_json({{"auc", s.auc},
                                 {"precision20", s.precision20},
                                 {"mean_iou", s.mean_iou},
                                 {"frames", s.frames}})
             .dump(2) +
         "\n";
}

}  // namespace roiflow::eval
