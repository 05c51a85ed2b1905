// Flow error metrics against ground truth (Baker et al., IJCV 2011), over the known ground-truth
// pixels (|u| or |v| > 1e9, or NaN, is unknown) outside the non-zero pixels of an optional
// exclude mask: EPE = |(u, v) - (ug, vg)|; AE = the angle between (u, v, 1) and (ug, vg, 1) in
// degrees; R1, R3 = the percentage of pixels with EPE > 1 and > 3; Fl = the percentage with EPE >
// 3 and > 5 % of |(ug, vg)| (KITTI's outlier rate).
//
//   const cv::Mat truth(frame_t.size(), CV_32FC2, cv::Scalar(1.f, 0.f));
//   const cv::Mat estimate(frame_t.size(), CV_32FC2, cv::Scalar(1.1f, 0.f));
//   const roiflow::flow::FlowErrors e = roiflow::flow::flow_errors(estimate, truth);
//   std::cout << "AAE " << e.aae_deg << " deg, EPE " << e.epe << " px\n";  // EPE 0.1
#pragma once

#include <opencv2/core.hpp>

namespace roiflow::flow {

struct FlowErrors {
  double aae_deg = 0;    // mean angular error, degrees
  double epe = 0;        // mean endpoint error, pixels
  double r1 = 0;         // % of pixels with EPE > 1
  double r3 = 0;         // % of pixels with EPE > 3
  double fl = 0;         // % of pixels with EPE > 3 and EPE > 0.05 |ground truth| (KITTI Fl)
  long long pixels = 0;  // pixels counted
};

// Flow with |u| or |v| above this is unknown (Middlebury's convention).
inline constexpr float kUnknownFlowThreshold = 1e9f;

bool is_known_flow(float u, float v);

// Throws roiflow::Error when types or sizes differ (message gives both sizes), and when the
// estimate is NaN or infinite at a counted pixel (a silently wrong mean is worse).
// No counted pixel: all metrics 0 and pixels 0, for the caller to judge.
FlowErrors flow_errors(const cv::Mat& estimate, const cv::Mat& ground_truth,
                       const cv::Mat& exclude = cv::Mat());

// Per-pixel endpoint error (CV_32FC1), 0 at unknown ground-truth pixels; throws as above.
cv::Mat endpoint_error_image(const cv::Mat& estimate, const cv::Mat& ground_truth);

}  // namespace roiflow::flow
