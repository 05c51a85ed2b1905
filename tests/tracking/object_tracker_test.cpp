#include "tracking/object_tracker.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <vector>

#include "eval/otb_score.hpp"
#include "eval/tracking_scene.hpp"
#include "test_util.hpp"

namespace roiflow::tracking {
namespace {

eval::TrackingScene scene(int frames) {
  eval::TrackingSceneParams p;
  p.size = cv::Size(320, 240);
  p.object = cv::Size2f(56, 36);
  p.frames = frames;
  p.jump = 0;
  return eval::TrackingScene(p);
}

TrackerInput input(const cv::Mat& bgr, long long index) {
  TrackerInput in;
  in.index = index;
  in.image = bgr;
  cv::cvtColor(bgr, in.gray, cv::COLOR_BGR2GRAY);
  return in;
}

// One init box: the same boxes as a Tracker with that init, id 1 on every frame.
TEST(ObjectTracker, OneInitBoxEqualsTracker) {
  const eval::TrackingScene s = scene(30);
  ObjectTrackerParams params;
  params.init = {s.box(0)};
  ObjectTracker objects(params);
  TrackerParams single = params.tracker;
  single.init = s.box(0);
  Tracker tracker(single);
  for (int i = 0; i < s.frames(); ++i) {
    const cv::Mat frame = s.render(i);
    const std::vector<TrackedObject> got = objects.update(input(frame, i));
    const TrackerOutput want = tracker.process(input(frame, i));
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].id, 1);
    EXPECT_EQ(got[0].box, want.box) << "frame " << i;
    EXPECT_EQ(got[0].lost, want.lost);
    EXPECT_EQ(objects.primary().box, want.box);
  }
  EXPECT_EQ(objects.frames(), s.frames());
}

// Two init boxes give ids 1 and 2; the second, on static background, stays where it was.
TEST(ObjectTracker, SeveralInitBoxesKeepTheirIds) {
  const eval::TrackingScene s = scene(20);
  ObjectTrackerParams params;
  params.init = {s.box(0), cv::Rect2f(250, 180, 40, 40)};
  ObjectTracker objects(params);
  std::vector<TrackedObject> last;
  for (int i = 0; i < s.frames(); ++i)
    last = objects.update(input(s.render(i), i));
  ASSERT_GE(last.size(), 1u);
  EXPECT_EQ(last[0].id, 1);
  EXPECT_GT(eval::iou(last[0].box, s.box(s.frames() - 1)), 0.5);
  if (last.size() == 2) {
    EXPECT_EQ(last[1].id, 2);
  }
}

// An object lost more than max_lost frames in a row is dropped: with init boxes for good.
TEST(ObjectTracker, MaxLostDropsTheObject) {
  const eval::TrackingScene s = scene(12);
  ObjectTrackerParams params;
  params.init = {s.box(0)};
  params.max_lost = 2;
  ObjectTracker objects(params);
  for (int i = 0; i < 6; ++i)
    ASSERT_EQ(objects.update(input(s.render(i), i)).size(), 1u);
  // The vehicle vanishes: an empty background from now on. The object is reported lost for
  // max_lost frames, then dropped for good (init boxes are not searched for again).
  std::vector<int> lost_frames;
  for (int i = 6; i < 12; ++i) {
    const std::vector<TrackedObject> got = objects.update(input(s.background(), i));
    if (got.empty()) break;
    ASSERT_TRUE(got[0].lost) << "frame " << i;
    lost_frames.push_back(got[0].lost_frames);
  }
  EXPECT_EQ(lost_frames, (std::vector<int>{1, 2}));
  EXPECT_TRUE(objects.update(input(s.render(0), 12)).empty());
}

TEST(ObjectTracker, BadParamsThrow) {
  ObjectTrackerParams params;
  params.max_lost = -1;
  EXPECT_NE(test::error_message([&] { ObjectTracker t(params); }).find("max_lost"),
            std::string::npos);
  params.max_lost = 0;
  params.init = {cv::Rect2f(0, 0, 1, 1)};
  EXPECT_NE(test::error_message([&] { ObjectTracker t(params); }).find("init box"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::tracking
