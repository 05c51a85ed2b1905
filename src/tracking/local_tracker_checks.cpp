// Self-awareness of the local treatment: the checks that find a measurement that cannot be
// right, so that the target is declared lost (and searched for) instead of followed wrongly.
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/local_tracker_impl.hpp"

namespace roiflow::tracking {

// The background's motion: the median flow over a grid of the region's pixels that lie outside
// the box by more than half an LK window (closer ones see the object too), with the share of the
// object's inliers that move unlike it.
void LocalTracker::Impl::measure_background(LocalResult& r, const cv::Rect2f& b) const {
  r.background_known = false;
  r.foreground = 0;
  if (r.region_flow.empty() || params.whole_frame) return;
  const float band = 0.5f * static_cast<float>(params.lk.patch * (1 << r.level));
  const cv::Rect2f inner(b.x - band, b.y - band, b.width + 2 * band, b.height + 2 * band);
  const cv::Rect& region = r.region;
  const int step = std::max(1, static_cast<int>(std::sqrt(region.area() / 400.0)));
  // Only textured pixels: LK's flow over a flat road or sky says nothing of its motion.
  const auto textured = static_cast<float>(std::max(params.min_texture, 0.05 * r.texture));
  std::vector<float> xs, ys;
  for (int y = step / 2; y < region.height; y += step) {
    const cv::Vec2f* row = r.region_flow.ptr<cv::Vec2f>(y);
    const float* cr = forward.confidence.ptr<float>(y);
    for (int x = step / 2; x < region.width; x += step) {
      if (cr[x] < textured ||
          inner.contains(cv::Point2f(static_cast<float>(region.x + x) + 0.5f,
                                     static_cast<float>(region.y + y) + 0.5f))) {
        continue;
      }
      xs.push_back(row[x][0]);
      ys.push_back(row[x][1]);
    }
  }
  if (xs.size() < 16) return;
  r.background = cv::Point2f(median(xs), median(ys));
  r.background_known = true;
  if (inliers.empty()) return;
  const float tol = foreground_tol(r.level);
  xs.clear();
  ys.clear();
  for (int i : inliers) {
    const cv::Point2f d = to[i] - from[i] - r.background;
    if (d.dot(d) > tol * tol) {
      xs.push_back(d.x);
      ys.push_back(d.y);
    }
  }
  r.foreground = static_cast<double>(xs.size()) / static_cast<double>(inliers.size());
  // Too few to be the target, or moving every which way (noise, the edges of a flow that is
  // uncertain at this level): the target moves with the background.
  if (xs.size() < 8 || r.foreground < 0.2) {
    r.foreground = 0;
    return;
  }
  const cv::Point2f apart(median(xs), median(ys));
  if (apart.dot(apart) < 4 * tol * tol) r.foreground = 0;
}

// Whether the flow's measurement holds: enough pixels pass the forward-backward check, their
// median error is low, the box has texture, and the size change between two frames is one a
// real object makes (`raw_scale`, before any clamping).
LostReason LocalTracker::Impl::check_flow(const LocalResult& r, double raw_scale) const {
  if (inliers.size() < 3 || r.inliers < params.min_inliers) return LostReason::FewInliers;
  if (r.fb_error > params.max_fb_error * (1 << r.level)) return LostReason::FbError;
  if (r.texture < params.min_texture) return LostReason::LowTexture;
  if (!(raw_scale >= 1.0 / kMaxScaleChange && raw_scale <= kMaxScaleChange)) {
    return LostReason::ScaleJump;
  }
  return LostReason::Found;
}

// Whether the state the step would reach can be right: a box about as large as the frame
// cannot be a tracked object's, and a target that moved unlike the background and now moves
// exactly with it, with none of its pixels moving otherwise, has been left behind by a box
// that latched onto the background.
LostReason LocalTracker::Impl::check_state(const LocalResult& r, cv::Point2f motion,
                                           const cv::Rect2f& next) const {
  const auto share = static_cast<float>(params.max_frame_share);
  if (next.width > share * static_cast<float>(size.width) ||
      next.height > share * static_cast<float>(size.height)) {
    return LostReason::TooLarge;
  }
  if (r.background_known && moving > params.moving_speed && r.foreground == 0 &&
      r.appearance < params.confident_appearance) {
    const cv::Point2f rel = motion - r.background;
    if (std::sqrt(rel.dot(rel)) < params.stop_share * moving) return LostReason::Background;
  }
  return LostReason::Found;
}

// The target's recent speed relative to the background (a running mean over a few frames).
void LocalTracker::Impl::learn_motion(const LocalResult& r, cv::Point2f motion) {
  if (!r.background_known) return;
  const cv::Point2f rel = motion - r.background;
  moving = 0.7 * moving + 0.3 * std::sqrt(static_cast<double>(rel.dot(rel)));
}

}  // namespace roiflow::tracking
