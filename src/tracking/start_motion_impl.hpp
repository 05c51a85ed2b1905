// The scene start's motion (internal to tracking, MotionDetector's part): what the frames' dense
// flow says of each pixel of the model's grid, and one object per distinct motion in a
// foreground part. MotionDetector::observe and detect_objects (motion_detector.hpp) use them.
//
//   #include "tracking/start_motion_impl.hpp"
//   using namespace roiflow;
//   const cv::Mat flow(240, 320, CV_32FC2, cv::Scalar(0, 0)), conf(240, 320, CV_32F, 1.0f);
//   cv::Mat textured;
//   const cv::Mat motion = tracking::detail::relative_motion(flow, conf, {160, 120}, 1.0,
//   textured); const cv::Mat state = tracking::detail::flow_motion_state(motion, 0.5);  // 1: all
//   still
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::tracking::detail {

// `back_flow` (full resolution, CV_32FC2: each pixel's displacement to the previous frame)
// averaged onto the model's grid (`size`), negated (the motion since the previous frame) and less
// the frame's median motion (a fixed camera's background: about zero; a shaking one's: its
// shift), in full-resolution pixels. `textured` (CV_8U, 255 or 0, `size`): where the window's
// smallest structure eigenvalue (`confidence`, full resolution) is at least `texture` times the
// frame's median one (all of it when `texture` is 0): elsewhere LK holds the coarser levels'
// motion, which spreads an object's motion over the uniform background around it.
cv::Mat relative_motion(const cv::Mat& back_flow, const cv::Mat& confidence, cv::Size size,
                        double texture, cv::Mat& textured);

// Per pixel of `motion` (relative_motion's): 2 where it moves by at least `moving` pixels, 1
// where by under half of that (it stands still), 0 between or where the motion is NaN.
cv::Mat flow_motion_state(const cv::Mat& motion, double moving);

// The boxes of the distinct motions of the component `label` of `labels` over `whole`
// (split_by_motion's modes, below), densest first, before the nested ones merge; none when no
// motion has `min_pixels` pixels.
std::vector<cv::Rect> motion_modes(const cv::Mat& labels, const cv::Mat& mask,
                                   const cv::Mat& motion, int label, const cv::Rect& whole,
                                   double moving, int min_pixels);

// The distinct motions of the component `label` of `labels` over `whole` (model resolution): its
// pixels that move (`mask` set, `motion` at least `moving`; NaN never does) gather around a few
// velocities. The densest velocity (a histogram of 1-pixel bins, each bin with its 8 neighbours)
// takes every pixel within a radius of it (a quarter of its speed, at least a pixel), then the
// densest of the rest, until one has fewer than `min_pixels` pixels. Each motion's box is the
// extent of its pixels (a vehicle seen on both sides of one crossing in front of it is one box),
// and boxes nested in another by `overlap` of the smaller merge (a walker's legs). With two boxes
// or more, appends them to `out` and returns true; with one, appends nothing and returns false.
// Pixels of no such velocity (the blend at the border between two objects) belong to none.
bool split_by_motion(const cv::Mat& labels, const cv::Mat& mask, const cv::Mat& motion, int label,
                     const cv::Rect& whole, double moving, int min_pixels, double overlap,
                     std::vector<cv::Rect>& out);

}  // namespace roiflow::tracking::detail
