// The motion split after the scene start (tracking/motion_split.hpp): which detections the
// objects followed flag, and the cut of a flagged blob by its pixels' dense flow, on synthetic
// scenes with exact boxes.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "hand_foreground.hpp"
#include "mot_scene.hpp"
#include "tracking/motion_split.hpp"

namespace roiflow {
namespace {

using test::foreground_over;
using test::MotScene;
using tracking::MultiTrackerParams;

tracking::TrackSet confirmed(const std::vector<cv::Rect2f>& boxes) {
  tracking::TrackSet s;
  s.frame = 10;
  s.size = {320, 240};
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    tracking::Track t;
    t.id = static_cast<long long>(i) + 1;
    t.box = boxes[i];
    t.filter = tracking::BoxFilter::start(boxes[i]);
    s.tracks.push_back(t);
  }
  return s;
}

// The boxes split_by_flow gives for `detection` between frames t and t+1 of `scene`.
std::vector<cv::Rect2f> split_of(const MotScene& scene, int t, const cv::Rect2f& detection,
                                 const tracking::Foreground& fg) {
  const MultiTrackerParams p;
  flow::Pyramid a, b;
  flow::build_pyramid(scene.gray(t), p.lk.levels, p.lk.sigma, a);
  flow::build_pyramid(scene.gray(t + 1), p.lk.levels, p.lk.sigma, b);
  flow::DenseLK lk(p.lk);
  return tracking::split_by_flow(detection, a, b, fg, lk, p);
}

TEST(MotionSplit, FlagsADetectionMuchLargerThanTheOneObjectItHolds) {
  const MultiTrackerParams p;
  const tracking::TrackSet s = confirmed({{100, 50, 40, 40}, {200, 50, 40, 40}});
  const tracking::Foreground fg = foreground_over({});
  const std::vector<tracking::Detection> d = {
      {{100, 50, 40, 120}, {}, 0},  // the first object and a tail three times its area
      {{100, 50, 42, 42}, {}, 0},   // the first object itself
      {{100, 50, 140, 40}, {}, 0},  // a merge of both: their LK follows them
      {{10, 150, 60, 60}, {}, 0}};  // no object
  const std::vector<std::size_t> which = tracking::split_candidates(s, d, fg, p);
  ASSERT_EQ(which.size(), 1u);
  EXPECT_EQ(which[0], 0u);
  MultiTrackerParams off = p;
  off.split_grow = 0;
  EXPECT_TRUE(tracking::split_candidates(s, d, fg, off).empty());
  tracking::Foreground start = fg;  // the scene start's motion: the detector split already
  start.motion = cv::Mat(240, 320, CV_32FC2, cv::Scalar(0, 0));
  EXPECT_TRUE(tracking::split_candidates(s, d, start, p).empty());
  MultiTrackerParams bad = p;
  bad.split_grow = 0.5;  // a detection smaller than its object is no tail
  EXPECT_THROW(bad.validate(), Error);
  bad = p;
  bad.split_keep = 0;
  EXPECT_THROW(bad.validate(), Error);
}

TEST(MotionSplit, CutsTheStillTailOfAMovingObjectsBlob) {
  // A vehicle moving right whose blob runs down over still background (the foreground of an
  // exposure change on an empty lane): the split keeps the vehicle's box only.
  const MotScene scene({320, 240}, {{{60, 40, 48, 36}, {3, 0}}});
  const int t = 10;
  const cv::Rect2f vehicle = scene.box(0, t + 1);
  const cv::Rect tail(static_cast<int>(vehicle.x), static_cast<int>(vehicle.br().y),
                      static_cast<int>(vehicle.width), 120);
  const cv::Rect2f blob = vehicle | cv::Rect2f(tail);
  const std::vector<cv::Rect2f> parts =
      split_of(scene, t, blob, foreground_over({cv::Rect(vehicle), tail}));
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_GE(test::box_iou(parts[0], vehicle), 0.6) << parts[0] << " vs " << vehicle;
  // The vehicle's blob alone (no still tail) is kept as it is.
  EXPECT_TRUE(split_of(scene, t, vehicle, foreground_over({cv::Rect(vehicle)})).empty());
}

TEST(MotionSplit, SplitsTwoObjectsMovingApartInOneBlob) {
  // Two vehicles side by side moving apart vertically, seen as one blob: one box each.
  const MotScene scene({320, 240}, {{{100, 60, 40, 60}, {0, 3}}, {{140, 140, 40, 60}, {0, -3}}});
  const int t = 4;
  const cv::Rect2f a = scene.box(0, t + 1), b = scene.box(1, t + 1);
  const std::vector<cv::Rect2f> parts =
      split_of(scene, t, a | b, foreground_over({cv::Rect(a), cv::Rect(b)}));
  ASSERT_EQ(parts.size(), 2u);
  for (const cv::Rect2f& truth : {a, b}) {
    double best = 0;
    for (const cv::Rect2f& part : parts)
      best = std::max(best, test::box_iou(part, truth));
    EXPECT_GE(best, 0.6) << truth;
  }
}

TEST(MotionSplit, ReplacesTheSplitDetectionsOnly) {
  const std::vector<tracking::Detection> d = {{{0, 0, 10, 10}, {5, 5}, 100},
                                              {{50, 50, 20, 40}, {60, 70}, 800}};
  const std::vector<tracking::Detection> out =
      tracking::apply_splits(d, {0, 1}, {{}, {{50, 50, 20, 20}, {50, 70, 20, 20}}});
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out.back().box, cv::Rect2f(0, 0, 10, 10));  // kept, smallest last
  EXPECT_FLOAT_EQ(static_cast<float>(out[0].score), 400.f);
}

}  // namespace
}  // namespace roiflow
