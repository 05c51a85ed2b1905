#include "tracking/box_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/tracking.hpp>
#include <opencv2/tracking/tracking_legacy.hpp>
#include <optional>

#include "core/error.hpp"
#include "core/text.hpp"
#include "flow/pyramid.hpp"

namespace roiflow::tracking {
namespace {

class RoiflowBoxTracker final : public BoxTracker {
 public:
  explicit RoiflowBoxTracker(const TrackerParams& params) : params_(params) {}

  BoxUpdate start(const video::Frame& frame, const cv::Mat&, const cv::Rect2f& box) override {
    params_.init = box;
    tracker_.emplace(params_, nullptr);
    return step(frame);
  }

  BoxUpdate next(const video::Frame& frame, const cv::Mat&) override {
    if (!tracker_) throw Error("roiflow tracker: next() before start()");
    return step(frame);
  }

 private:
  BoxUpdate step(const video::Frame& frame) {
    std::shared_ptr<const flow::Pyramid> pyramid;
    if (tracker_->wants_pyramid()) {
      pyramid = std::make_shared<flow::Pyramid>(
          flow::build_pyramid(frame.gray, tracker_->pyramid_levels(), tracker_->pyramid_sigma()));
    }
    const TrackerOutput out =
        tracker_->process({frame.index, frame.image, frame.gray, pyramid, frame.deferred_image});
    return {out.box, out.lost || !out.has_target};
  }

  TrackerParams params_;
  std::optional<Tracker> tracker_;
};

cv::Rect rounded(const cv::Rect2f& b) {
  return {static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(b.y)),
          static_cast<int>(std::lround(b.width)), static_cast<int>(std::lround(b.height))};
}

// cv::Tracker (CSRT, KCF): integer boxes.
class OpenCvBoxTracker final : public BoxTracker {
 public:
  explicit OpenCvBoxTracker(cv::Ptr<cv::Tracker> (*create)()) : create_(create) {}

  BoxUpdate start(const video::Frame&, const cv::Mat& bgr, const cv::Rect2f& box) override {
    box_ = box;
    tracker_ = create_();
    try {
      tracker_->init(bgr, rounded(box));
    } catch (const cv::Exception&) {
      tracker_.release();
    }
    return {box_, !tracker_};
  }

  BoxUpdate next(const video::Frame&, const cv::Mat& bgr) override {
    if (!tracker_) return {box_, true};
    cv::Rect out = rounded(box_);
    bool found = false;
    try {
      found = tracker_->update(bgr, out);
    } catch (const cv::Exception&) {
      found = false;
    }
    if (found) box_ = cv::Rect2f(out);
    return {box_, !found};
  }

 private:
  cv::Ptr<cv::Tracker> (*create_)();
  cv::Ptr<cv::Tracker> tracker_;
  cv::Rect2f box_;
};

// cv::legacy::Tracker (MOSSE, MedianFlow): boxes in doubles.
class LegacyBoxTracker final : public BoxTracker {
 public:
  explicit LegacyBoxTracker(cv::Ptr<cv::legacy::Tracker> (*create)()) : create_(create) {}

  BoxUpdate start(const video::Frame&, const cv::Mat& bgr, const cv::Rect2f& box) override {
    box_ = box;
    tracker_ = create_();
    bool ok = false;
    try {
      ok = tracker_->init(bgr, cv::Rect2d(box));
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok) tracker_.release();
    return {box_, !tracker_};
  }

  BoxUpdate next(const video::Frame&, const cv::Mat& bgr) override {
    if (!tracker_) return {box_, true};
    cv::Rect2d out(box_);
    bool found = false;
    try {
      found = tracker_->update(bgr, out);
    } catch (const cv::Exception&) {
      found = false;
    }
    if (found) box_ = cv::Rect2f(out);
    return {box_, !found};
  }

 private:
  cv::Ptr<cv::legacy::Tracker> (*create_)();
  cv::Ptr<cv::legacy::Tracker> tracker_;
  cv::Rect2f box_;
};

cv::Ptr<cv::Tracker> create_csrt() {
  return cv::TrackerCSRT::create();
}
cv::Ptr<cv::Tracker> create_kcf() {
  return cv::TrackerKCF::create();
}
cv::Ptr<cv::legacy::Tracker> create_mosse() {
  return cv::legacy::TrackerMOSSE::create();
}
cv::Ptr<cv::legacy::Tracker> create_medianflow() {
  return cv::legacy::TrackerMedianFlow::create();
}

}  // namespace

const std::vector<std::string>& box_tracker_names() {
  static const std::vector<std::string> names = {"roiflow", "csrt", "kcf", "mosse", "medianflow"};
  return names;
}

std::unique_ptr<BoxTracker> make_box_tracker(std::string_view name, const TrackerParams& roiflow) {
  if (name == "roiflow") return std::make_unique<RoiflowBoxTracker>(roiflow);
  if (name == "csrt") return std::make_unique<OpenCvBoxTracker>(&create_csrt);
  if (name == "kcf") return std::make_unique<OpenCvBoxTracker>(&create_kcf);
  if (name == "mosse") return std::make_unique<LegacyBoxTracker>(&create_mosse);
  if (name == "medianflow") return std::make_unique<LegacyBoxTracker>(&create_medianflow);
  throw Error(box_tracker_check(name));
}

std::string box_tracker_check(std::string_view name) {
  const std::vector<std::string>& known = box_tracker_names();
  if (std::find(known.begin(), known.end(), name) != known.end()) return {};
  return "unknown tracker '" + std::string(name) + "' (known: " + joined(known) + ")";
}

cv::Mat bgr_picture(const video::Frame& frame) {
  const cv::Mat picture = frame.picture();
  if (picture.channels() == 3) return picture;
  cv::Mat bgr;
  cv::cvtColor(picture, bgr, picture.channels() == 4 ? cv::COLOR_BGRA2BGR : cv::COLOR_GRAY2BGR);
  return bgr;
}

}  // namespace roiflow::tracking
