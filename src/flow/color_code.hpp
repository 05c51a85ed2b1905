// Middlebury colour coding of flow (Baker et al. 2011; the paper's Fig. 10): hue gives the
// direction (the 55-colour Middlebury wheel), saturation the magnitude relative to
// `max_magnitude` (<= 0: the largest known magnitude in the field); unknown pixels (|u| or |v| >
// 1e9, NaN) are black. Also the wheel as a legend and arrows drawn over an image.
//
//   const cv::Mat flow(frame_t.size(), CV_32FC2, cv::Scalar(1.5f, -0.5f));
//   const cv::Mat coded = roiflow::flow::flow_to_color(flow);     // CV_8UC3, for cv::imwrite
//   const cv::Mat legend = roiflow::flow::color_wheel_legend(151);
//   const cv::Mat arrows = roiflow::flow::draw_flow_vectors(bgr, flow, 16);
#pragma once

#include <opencv2/core.hpp>

namespace roiflow::flow {

cv::Mat flow_to_color(const cv::Mat& flow, float max_magnitude = -1.f);
// A square legend of side `size` >= 3 (odd sizes centre exactly): each pixel coloured by its
// own offset from the centre, the inscribed circle's rim at full magnitude; white outside the
// circle (black would read as "unknown").
cv::Mat color_wheel_legend(int size = 151);
// Draws green flow vectors every `step` pixels (from step/2), skipping unknown flow, on a BGR
// copy of `image` (CV_8UC1 or CV_8UC3, same size as `flow`); arrows scaled by `scale`.
cv::Mat draw_flow_vectors(const cv::Mat& image, const cv::Mat& flow, int step = 16,
                          float scale = 1.f);

}  // namespace roiflow::flow
