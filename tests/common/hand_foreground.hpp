// A hand-made motion-detector foreground for the tracking tests: a 320x240 frame at full
// resolution (the model's scale 1) whose pixels inside `boxes` are moving, with its integral.
//
//   const roiflow::tracking::Foreground fg = roiflow::test::foreground_over({{40, 40, 14, 9}});
#pragma once

#include <opencv2/imgproc.hpp>
#include <vector>

#include "tracking/motion_detector.hpp"

namespace roiflow::test {

inline tracking::Foreground foreground_over(const std::vector<cv::Rect>& boxes) {
  tracking::Foreground fg;
  fg.observed = 100;
  fg.scale = 1;
  fg.frame_size = {320, 240};
  fg.mask = cv::Mat(240, 320, CV_8U, cv::Scalar(0));
  for (const cv::Rect& b : boxes)
    fg.mask(b) = 255;
  cv::Mat ones;
  cv::threshold(fg.mask, ones, 0, 1, cv::THRESH_BINARY);
  cv::integral(ones, fg.integral, CV_32S);
  return fg;
}

}  // namespace roiflow::test
