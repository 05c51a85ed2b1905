#include "tracking/banded_mog2.hpp"

#include <algorithm>
#include <string>

#include "core/error.hpp"

namespace roiflow::tracking {

namespace {

// Bands of at least kBandRows rows (each takes its share of the rest), at most kMaxBands.
constexpr int kBandRows = 32;
constexpr int kMaxBands = 16;

}  // namespace

void BandedMog2::apply(const cv::Mat& image, cv::Mat& mask, double learning_rate) {
  if (models_.empty()) {
    const int count = std::clamp(image.rows / kBandRows, 1, kMaxBands);
    for (int i = 0; i < count; ++i) {
      bands_.emplace_back(image.rows * i / count, image.rows * (i + 1) / count);
      models_.push_back(cv::createBackgroundSubtractorMOG2(params_.history, params_.var_threshold,
                                                           params_.shadows));
      if (params_.shadow_threshold) models_.back()->setShadowThreshold(*params_.shadow_threshold);
      if (params_.background_ratio) models_.back()->setBackgroundRatio(*params_.background_ratio);
    }
  } else if (image.rows != bands_.back().end) {
    throw Error("background model: frame of " + std::to_string(image.rows) +
                " rows after frames of " + std::to_string(bands_.back().end));
  }
  mask.create(image.size(), CV_8U);
  // One band after the other: the bands learnt in parallel through cv::parallel_for_ gave TSan
  // reports (OpenCV's loop joins are not instrumented) inside the graph's nodes; they are to run
  // on roiflow's own executor instead.
  for (std::size_t i = 0; i < models_.size(); ++i) {
    cv::Mat band = mask.rowRange(bands_[i]);
    models_[i]->apply(image.rowRange(bands_[i]), band, learning_rate);
  }
}

}  // namespace roiflow::tracking
