// Flow error metrics against ground truth (Baker et al., IJCV 2011).
//
//   FlowErrors e = roiflow::flow::flow_errors(estimate, ground_truth);
//   std::printf("AAE %.2f deg, EPE %.3f px\n", e.aae_deg, e.epe);
//
// Over known ground-truth pixels only (|u| or |v| > 1e9, or NaN, is unknown) and, when
// `exclude` is given (CV_8UC1, same size), outside its non-zero pixels.
//   EPE = |(u, v) - (ug, vg)|;  AE = angle between (u, v, 1) and (ug, vg, 1) in degrees;
//   R1, R3 = percentage of pixels with EPE > 1 and > 3;
//   Fl = percentage of pixels with EPE > 3 and EPE > 5 % of |(ug, vg)| (KITTI's outlier rate).
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
