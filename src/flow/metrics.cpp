#include "flow/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace roiflow::flow {
namespace {

std::string describe(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows) + " " + cv::typeToString(m.type());
}

void check_pair(const char* caller, const cv::Mat& estimate, const cv::Mat& ground_truth) {
  if (estimate.type() != CV_32FC2 || ground_truth.type() != CV_32FC2 ||
      estimate.size() != ground_truth.size()) {
    throw Error(std::string(caller) + ": estimate is " + describe(estimate) + ", ground truth is " +
                describe(ground_truth) + " (both must be CV_32FC2, same size)");
  }
}

// A NaN or infinite estimate at a counted pixel would poison the means silently; better loud.
void check_estimate(float u, float v, int x, int y) {
  if (!std::isfinite(u) || !std::isfinite(v)) {
    throw Error("estimate has non-finite flow (" + std::to_string(u) + ", " + std::to_string(v) +
                ") at (" + std::to_string(x) + "," + std::to_string(y) + ")");
  }
}

}  // namespace

bool is_known_flow(float u, float v) {
  // NaN and infinity fail these comparisons, so they are unknown too.
  return std::abs(u) <= kUnknownFlowThreshold && std::abs(v) <= kUnknownFlowThreshold;
}

FlowErrors flow_errors(const cv::Mat& estimate, const cv::Mat& ground_truth,
                       const cv::Mat& exclude) {
  check_pair("flow_errors", estimate, ground_truth);
  if (!exclude.empty() && (exclude.type() != CV_8UC1 || exclude.size() != estimate.size())) {
    throw Error("flow_errors: exclude mask is " + describe(exclude) + ", flow is " +
                describe(estimate) + " (mask must be CV_8UC1, same size)");
  }

  double sum_angle = 0;
  double sum_epe = 0;
  long long pixels = 0;
  long long over1 = 0;
  long long over3 = 0;
  long long outliers = 0;
  for (int y = 0; y < estimate.rows; ++y) {
    const float* est = estimate.ptr<float>(y);
    const float* gt = ground_truth.ptr<float>(y);
    const uchar* mask = exclude.empty() ? nullptr : exclude.ptr<uchar>(y);
    for (int x = 0; x < estimate.cols; ++x) {
      if ((mask && mask[x]) || !is_known_flow(gt[2 * x], gt[2 * x + 1])) continue;
      check_estimate(est[2 * x], est[2 * x + 1], x, y);
      const double u = est[2 * x];
      const double v = est[2 * x + 1];
      const double ug = gt[2 * x];
      const double vg = gt[2 * x + 1];
      const double du = u - ug;
      const double dv = v - vg;
      const double epe = std::sqrt(du * du + dv * dv);
      const double cosine =
          (1 + u * ug + v * vg) / std::sqrt((1 + u * u + v * v) * (1 + ug * ug + vg * vg));
      sum_angle += std::acos(std::clamp(cosine, -1.0, 1.0));
      sum_epe += epe;
      over1 += epe > 1;
      over3 += epe > 3;
      outliers += epe > 3 && epe > 0.05 * std::sqrt(ug * ug + vg * vg);
      ++pixels;
    }
  }

  FlowErrors e;
  e.pixels = pixels;
  if (pixels == 0) return e;
  const double n = static_cast<double>(pixels);
  e.aae_deg = sum_angle / n * (180.0 / std::numbers::pi);
  e.epe = sum_epe / n;
  e.r1 = 100.0 * static_cast<double>(over1) / n;
  e.r3 = 100.0 * static_cast<double>(over3) / n;
  e.fl = 100.0 * static_cast<double>(outliers) / n;
  return e;
}

cv::Mat endpoint_error_image(const cv::Mat& estimate, const cv::Mat& ground_truth) {
  check_pair("endpoint_error_image", estimate, ground_truth);
  cv::Mat error(estimate.size(), CV_32FC1, cv::Scalar(0));
  for (int y = 0; y < estimate.rows; ++y) {
    const float* est = estimate.ptr<float>(y);
    const float* gt = ground_truth.ptr<float>(y);
    float* out = error.ptr<float>(y);
    for (int x = 0; x < estimate.cols; ++x) {
      const float ug = gt[2 * x];
      const float vg = gt[2 * x + 1];
      if (!is_known_flow(ug, vg)) continue;
      check_estimate(est[2 * x], est[2 * x + 1], x, y);
      const double du = double{est[2 * x]} - ug;
      const double dv = double{est[2 * x + 1]} - vg;
      out[x] = static_cast<float>(std::sqrt(du * du + dv * dv));
    }
  }
  return error;
}

}  // namespace roiflow::flow
