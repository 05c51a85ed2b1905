// DeferredImage: a picture that is made only when somebody first asks for it, on the asking
// thread, once. A video's frames carry their BGR picture this way when the source was asked to
// defer it (VideoSourceParams::defer_colour): the tracker needs only the gray frame for most
// frames, and converting the decoder's planes to BGR was 40 % of decoding (pipeline_bench,
// synthetic 640x480 MPEG-4).
//
//   stages::Frame f = *source.next();
//   cv::Mat bgr = f.picture();   // f.image, else the deferred picture (made now), else f.gray
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <utility>

namespace roiflow::stages {

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

}  // namespace roiflow::stages
