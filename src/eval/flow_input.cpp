#include "eval/flow_input.hpp"

#include <filesystem>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/flo_io.hpp"
#include "eval/image_io.hpp"

namespace roiflow::eval {

FlowInput read_flow_input(const std::string& frame0, const std::string& frame1,
                          const std::string& ground_truth) {
  for (const std::string& image : {frame0, frame1}) {
    std::error_code ec;
    if (std::filesystem::is_directory(image, ec))
      throw Error("image '" + image + "' is a directory, not an image file");
  }
  FlowInput in;
  in.frame0 = read_gray(frame0);
  check_frame_size(in.frame0.size(), "image '" + frame0 + "'");
  in.frame1 = read_gray(frame1);
  check_frame_size(in.frame1.size(), "image '" + frame1 + "'");
  if (in.frame0.size() != in.frame1.size()) {
    throw Error("'" + frame0 + "' is " + size_text(in.frame0.size()) + " but '" + frame1 + "' is " +
                size_text(in.frame1.size()));
  }
  if (!ground_truth.empty()) {
    in.truth = read_flo(ground_truth);
    if (in.truth.size() != in.frame0.size()) {
      throw Error("--gt: '" + ground_truth + "' is " + size_text(in.truth.size()) + " but '" +
                  frame0 + "' is " + size_text(in.frame0.size()));
    }
  }
  in.source = frame0 + " -> " + frame1;
  return in;
}

std::vector<SceneKind> synthetic_scene_kinds() {
  return {SceneKind::Translation, SceneKind::Rotation, SceneKind::Zoom, SceneKind::NonRigid,
          SceneKind::MovingObject};
}

FlowInput flow_input(const std::string& frame0, const std::string& frame1,
                     const std::string& ground_truth, const std::string& scene, cv::Size size) {
  if (scene.empty()) {
    if (frame1.empty()) throw UsageError("flow needs two images A B, or --synthetic [scene]");
    return read_flow_input(frame0, frame1, ground_truth);
  }
  if (!frame0.empty()) throw UsageError("give either two images A B or --synthetic, not both");
  if (!ground_truth.empty()) {
    throw UsageError("--gt: a --synthetic scene brings its own ground truth");
  }
  return synthetic_flow_input(scene, size);
}

FlowInput synthetic_flow_input(const std::string& name, cv::Size size) {
  for (SceneKind kind : synthetic_scene_kinds()) {
    if (name != to_string(kind)) continue;
    Scene scene = make_scene(kind, size);
    return {scene.frame0, scene.frame1, scene.flow, "synthetic " + name};
  }
  throw Error("unknown synthetic scene '" + name + "'");
}

std::string errors_text(const flow::FlowErrors& e) {
  return "AAE " + fixed(e.aae_deg, 3) + " deg, EPE " + fixed(e.epe, 4) + " px, R1 " +
         fixed(e.r1, 2) + " %, R3 " + fixed(e.r3, 2) + " %";
}

std::vector<EvalPair> select_pairs(const std::string& dir, const FindOptions& find,
                                   const std::vector<std::vector<std::string>>& triples,
                                   const std::vector<std::string>& exclude_masks,
                                   std::vector<std::string>* skipped) {
  if (dir.empty() && triples.empty()) {
    throw UsageError(
        "eval needs a Middlebury, Sintel or KITTI directory DIR or at least one --pair A B GT");
  }
  if (!dir.empty()) return find_pairs(dir, find, skipped);
  return listed_pairs(triples, exclude_masks);
}

std::vector<EvalPair> middlebury_or_listed(const std::string& dir,
                                           const std::vector<std::vector<std::string>>& triples,
                                           int max_pairs) {
  if (dir.empty() && triples.empty()) {
    throw UsageError("sweep needs a Middlebury directory DIR or at least one --pair A B GT");
  }
  std::vector<EvalPair> pairs = dir.empty() ? listed_pairs(triples) : find_middlebury(dir);
  if (max_pairs > 0 && pairs.size() > static_cast<std::size_t>(max_pairs)) {
    pairs.resize(static_cast<std::size_t>(max_pairs));
  }
  return pairs;
}

std::vector<EvalPair> listed_pairs(const std::vector<std::vector<std::string>>& triples,
                                   const std::vector<std::string>& exclude_masks) {
  if (!exclude_masks.empty() && exclude_masks.size() != triples.size()) {
    throw UsageError("--exclude-mask: got " + std::to_string(exclude_masks.size()) + " masks for " +
                     std::to_string(triples.size()) +
                     " pairs (give one per --pair, in the same order)");
  }
  std::vector<EvalPair> pairs;
  for (std::size_t i = 0; i < triples.size(); ++i) {
    const std::vector<std::string>& p = triples[i];
    pairs.push_back({"pair" + std::to_string(i + 1), p.at(0), p.at(1), p.at(2),
                     exclude_masks.empty() ? "" : exclude_masks[i]});
  }
  return pairs;
}

}  // namespace roiflow::eval
