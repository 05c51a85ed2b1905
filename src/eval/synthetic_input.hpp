// The "synthetic:" input spec: a generated video in place of a file, and its ground truth.
//
//   const auto spec = roiflow::eval::parse_synthetic_input("synthetic:300:640x480:16");
//   // spec.frames == 300, spec.size == {640, 480}, spec.objects == 16
//   roiflow::eval::TrafficScene scene(roiflow::eval::traffic_params(spec));
//   roiflow::eval::write_mot("gt_mot.txt", scene.ground_truth());
//
// Grammar: synthetic:FRAMES[:WxH][:OBJECTS]. FRAMES in 1..10^9; WxH each side 64..8192
// (default 640x480) and within eval::check_frame_size; OBJECTS in 1..256. Without OBJECTS the
// input is eval::TrackingScene's single vehicle (video::VideoSource plays it forwards and
// backwards); with OBJECTS it is eval::TrafficScene with that many vehicles, FRAMES long, whose
// ground_truth() holds every box. "synthetic:300:16" is 640x480 with 16 vehicles.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "eval/traffic_scene.hpp"

namespace roiflow::eval {

struct SyntheticInput {
  long long frames = 0;
  cv::Size size{640, 480};
  int objects = 0;  // 0: the single-vehicle tracking scene
};

inline constexpr std::string_view kSyntheticInputPrefix = "synthetic:";

// Whether `input` starts with "synthetic:".
bool is_synthetic_input(std::string_view input);
// Throws roiflow::Error "bad synthetic input 'INPUT': why (expected ...)" when malformed.
SyntheticInput parse_synthetic_input(const std::string& input);
// The traffic scene of a spec with objects > 0 (seed 1, the default camera noise).
TrafficSceneParams traffic_params(const SyntheticInput& spec);

}  // namespace roiflow::eval
