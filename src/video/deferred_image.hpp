// A picture made only when somebody first asks for it, on the asking thread, once (thread-safe).
// A video's frames carry their BGR picture this way when the source defers colour: the tracker
// needs only the gray frame for most frames.
//
//   const auto deferred = std::make_shared<const roiflow::video::DeferredImage>(
//       [&] { return bgr.clone(); });                // not run yet
//   const cv::Mat picture = roiflow::video::picture_of(cv::Mat(), deferred, frame_t);  // now
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <utility>

namespace roiflow::video {

class DeferredImage {
 public:
  explicit DeferredImage(std::function<cv::Mat()> make) : make_(std::move(make)) {}

  // The picture: made by the first call, the same Mat afterwards (the maker and what it holds
  // are released then). Thread-safe; a call whose maker throws leaves it unmade (the next call
  // tries again) and rethrows.
  cv::Mat get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (image_.empty() && make_) {
      image_ = make_();
      make_ = nullptr;
    }
    return image_;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::function<cv::Mat()> make_;
  mutable cv::Mat image_;
};

// What Frame::picture() and TrackerInput::picture() answer: `image` when there is one, else the
// deferred picture, else `gray`.
inline cv::Mat picture_of(const cv::Mat& image,
                          const std::shared_ptr<const DeferredImage>& deferred,
                          const cv::Mat& gray) {
  if (!image.empty()) return image;
  if (deferred) return deferred->get();
  return gray;
}

}  // namespace roiflow::video
