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

void BandedMog2::apply(const cv::Mat& image, cv::Mat& mask, double learning_rate,
                       const Executor* executor) {
  if (models_.empty()) {
    // One band per thread that can run one: more would only add models and their setup.
    const int threads = executor != nullptr ? std::min(executor->concurrency(), kMaxBands) : 1;
    const int count = std::clamp(image.rows / kBandRows, 1, std::max(threads, 1));
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
  // The bands on roiflow's executor, not cv::parallel_for_: inside the graph's nodes OpenCV's
  // loop joins are not instrumented for ThreadSanitizer, TBB's are. A band under MOG2's
  // 65536-pixel stripe (320 columns by up to 204 rows) runs on the calling thread.
  const auto run = [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      const auto b = static_cast<std::size_t>(i);
      cv::Mat band = mask.rowRange(bands_[b]);
      models_[b]->apply(image.rowRange(bands_[b]), band, learning_rate);
    }
  };
  const int count = static_cast<int>(models_.size());
  if (count > 1) {
    executor->for_range(0, count, 1, run);  // (several bands only where an executor was given)
  } else {
    run(0, count);
  }
}

}  // namespace roiflow::tracking
