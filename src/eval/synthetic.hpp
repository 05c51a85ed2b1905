// Synthetic image pairs with exact ground-truth flow, for tests, demos and benchmarks. Frames are
// rendered from a band-limited continuous texture (random multi-scale sinusoids and soft blobs),
// so sub-pixel motion is exact: frame1(x) = texture(W^-1(x)), and the ground truth is the forward
// flow W(x) - x at every pixel of frame0 (CV_32FC2, u right, v down).
//
//   #include "flow/dense_lk.hpp"
//   #include "flow/metrics.hpp"
//   const roiflow::eval::Scene s =
//       roiflow::eval::make_scene(roiflow::eval::SceneKind::Rotation, {320, 240}, /*seed=*/7);
//   const auto r = roiflow::flow::dense_flow(s.frame0, s.frame1, roiflow::flow::LkParams::paper());
//   std::cout << roiflow::flow::flow_errors(r.flow, s.flow).epe << " px\n";
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace roiflow::eval {

enum class SceneKind {
  Translation,   // sub-pixel translation (parameter: (1.3, -0.7) px by default)
  Rotation,      // 3 degrees about the centre ((w-1)/2, (h-1)/2), counter-clockwise on
                 // screen: y points down, so a point right of the centre moves up (v < 0)
  Zoom,          // isotropic scale about the centre (+4 %)
  NonRigid,      // smooth sinusoidal deformation field, amplitude ~2 px
  MovingObject,  // textured rectangle moving over a differently moving textured background
};

struct Scene {
  cv::Mat frame0;  // CV_8UC1
  cv::Mat frame1;  // CV_8UC1
  cv::Mat flow;    // CV_32FC2 ground truth, frame0 -> frame1
};

// Throws roiflow::Error when a side of `size` is outside 8..8192.
Scene make_scene(SceneKind kind, cv::Size size, std::uint64_t seed = 1);

// A translation by an arbitrary (dx, dy), for speed and range tests. Throws roiflow::Error
// also when |dx| or |dy| exceeds 8192.
Scene make_translation(cv::Size size, cv::Point2f motion, std::uint64_t seed = 1);

const char* to_string(SceneKind kind);

}  // namespace roiflow::eval
