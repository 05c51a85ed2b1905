// Middlebury colour coding of flow (Baker et al. 2011; the paper's Fig. 10).
//
//   cv::Mat bgr = roiflow::flow::flow_to_color(flow);        // CV_8UC3, for cv::imwrite
//   cv::Mat key = roiflow::flow::color_wheel_legend(151);    // the wheel, as a legend
//
// Hue gives the direction (the 55-colour Middlebury wheel: RY 15, YG 6, GC 4, CB 11, BM 13,
// MR 6), saturation the magnitude relative to `max_magnitude` (<= 0: the field's robust
// maximum, robust_max_magnitude). Magnitudes beyond it keep their hue, darkened (Middlebury's
// rule). Unknown pixels (|u| or |v| > 1e9, NaN) are black.
//
// The robust maximum is a high percentile of the known magnitudes rather than their maximum,
// so that a few wild vectors (border outliers of an estimate, a handful of pixels) do not
// wash the whole picture out; on a field with fewer than 1 / (1 - percentile) pixels it is the
// maximum. To compare an estimate with its ground truth, colour both with the truth's
// max_magnitude().
//
//   const float scale = roiflow::flow::max_magnitude(truth);
//   cv::Mat a = roiflow::flow::flow_to_color(estimate, scale), b = flow_to_color(truth, scale);
#pragma once

#include <opencv2/core.hpp>

namespace roiflow::flow {

// Percentile (of the known magnitudes) flow_to_color saturates at by default.
inline constexpr double kRobustMagnitudePercentile = 99.0;

cv::Mat flow_to_color(const cv::Mat& flow, float max_magnitude = -1.f);
// The nearest-rank `percentile` (in (0, 100]) of the known vectors' magnitudes of a CV_32FC2
// field; 0 when none is known. Throws roiflow::Error on another type or percentile.
float robust_max_magnitude(const cv::Mat& flow, double percentile = kRobustMagnitudePercentile);
// The largest known magnitude (robust_max_magnitude at 100).
float max_magnitude(const cv::Mat& flow);
// A square legend of side `size` >= 3 (odd sizes centre exactly): each pixel coloured by its
// own offset from the centre, the inscribed circle's rim at full magnitude; white outside the
// circle (black would read as "unknown").
cv::Mat color_wheel_legend(int size = 151);
// Draws green flow vectors every `step` pixels (from step/2), skipping unknown flow, on a BGR
// copy of `image` (CV_8UC1 or CV_8UC3, same size as `flow`); arrows scaled by `scale`.
cv::Mat draw_flow_vectors(const cv::Mat& image, const cv::Mat& flow, int step = 16,
                          float scale = 1.f);

}  // namespace roiflow::flow
