// The scene start with the frames' flow (MotionDetector::observe with dense LK back to the
// previous frame, detect_objects' split by motion): synthetic scenes with exact boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.hpp"
#include "eval/traffic_scene.hpp"
#include "flow/dense_lk.hpp"
#include "mot_scene.hpp"
#include "tracking/motion_detector.hpp"

namespace roiflow {
namespace {

using test::MotScene;

// Observes `picture` with, while the detector wants it, dense LK from it back to `previous`.
tracking::Foreground observe_with_flow(tracking::MotionDetector& detector, flow::DenseLK& lk,
                                       const cv::Mat& picture, const cv::Mat& previous) {
  if (!detector.wants_flow() || previous.empty()) return detector.observe(picture);
  cv::Mat now, before;
  cv::cvtColor(picture, now, cv::COLOR_BGR2GRAY);
  cv::cvtColor(previous, before, cv::COLOR_BGR2GRAY);
  const flow::FlowResult back = lk.calc(now, before);
  return detector.observe(picture, &back);
}

TEST(MotionDetector, WantsTheFlowInTheSceneStartOnly) {
  tracking::MotionDetectorParams p;
  p.start_frames = 3;
  EXPECT_FALSE(tracking::wants_flow(p, 0));  // no previous frame
  for (long long i = 1; i <= 3; ++i)
    EXPECT_TRUE(tracking::wants_flow(p, i)) << i;
  EXPECT_FALSE(tracking::wants_flow(p, 4));
  tracking::MotionDetector detector(p);
  const MotScene scene({240, 160}, {{{20, 60, 24, 40}, {4, 0}}});
  for (int t = 0; t < 6; ++t) {
    EXPECT_EQ(detector.wants_flow(), tracking::wants_flow(p, t)) << t;
    detector.observe(scene.frame(t));
  }
  p.start_motion = 0;
  EXPECT_FALSE(tracking::wants_flow(p, 1));
}

TEST(MotionDetector, TheFramesFlowFindsVehiclesWholeFromTheSecondFrame) {
  // The scene start with the frames' flow (the global treatment's motion: a fixed camera's
  // background does not move): vehicles moving in the first frame are found whole (IoU >= 0.5
  // with their exact boxes) from the second frame on, where the background model alone finds
  // nothing during its warm-up and then slices and ghosts.
  const eval::TrafficScene scene({.size = {640, 480}, .frames = 21, .objects = 8});
  int matched[2] = {0, 0}, in_view = 0, second = 0;
  for (const bool with_flow : {false, true}) {
    tracking::MotionDetectorParams p;
    tracking::MotionDetector detector(p);
    flow::DenseLK lk;
    cv::Mat previous;
    for (int t = 0; t <= 20; ++t) {
      const cv::Mat picture = scene.render(t);
      const tracking::Foreground fg = with_flow ? observe_with_flow(detector, lk, picture, previous)
                                                : detector.observe(picture);
      previous = picture;
      EXPECT_EQ(fg.motion.empty(), !with_flow || t == 0) << t;
      const std::vector<tracking::Detection> found = tracking::detect_objects(fg, p);
      for (const eval::MotBox& truth : scene.boxes(t)) {
        const cv::Rect2f gt(
            static_cast<float>(truth.box.x - 1), static_cast<float>(truth.box.y - 1),
            static_cast<float>(truth.box.width), static_cast<float>(truth.box.height));
        double best = 0;
        for (const tracking::Detection& d : found)
          best = std::max(best, test::box_iou(d.box, gt));
        if (best >= 0.5) {
          ++matched[with_flow ? 1 : 0];
          if (with_flow && t == 1) ++second;
        }
        if (with_flow && t == 1) ++in_view;
      }
    }
  }
  EXPECT_GE(2 * second, in_view);          // half the vehicles from the second frame
  EXPECT_GE(matched[1], matched[0] + 40);  // of about 160 vehicle boxes
}

TEST(MotionDetector, TheFramesFlowAbsorbsAGhostAtOnce) {
  // An object drives away from the place it stood in when the model learnt the first frame:
  // with the frames' flow, that place (it does not move) is background as soon as the object
  // has left it; the change test needs `change_frames` more frames to tell.
  const MotScene scene({240, 160}, {{{20, 60, 24, 40}, {4, 0}}});
  const cv::Rect2f ghost = scene.box(0, 0);
  double share[2] = {0, 0};
  for (const bool with_flow : {false, true}) {
    tracking::MotionDetector detector;
    flow::DenseLK lk;
    cv::Mat previous;
    for (int t = 0; t <= 8; ++t) {
      const cv::Mat picture = scene.frame(t);
      const tracking::Foreground fg = with_flow ? observe_with_flow(detector, lk, picture, previous)
                                                : detector.observe(picture);
      previous = picture;
      if (t == 8) {
        share[with_flow ? 1 : 0] = fg.moving_share(ghost);
        EXPECT_GT(fg.moving_share(scene.box(0, t)), 0.8) << with_flow;
      }
    }
  }
  EXPECT_GT(share[0], 0.3);
  EXPECT_LT(share[1], 0.05);
}

TEST(DetectObjects, SplitsAPartWhosePixelsMoveApart) {
  // Two objects crossing, one drawn over the other, seen as one foreground part: with the scene
  // start's motion, one object per distinct motion (the lower one's box whole on both sides of
  // the upper one); with one motion (or none), one object.
  const cv::Rect along(20, 50, 64, 20), across(60, 24, 16, 64);
  tracking::Foreground fg;
  fg.observed = 10;
  fg.scale = 1;
  fg.frame_size = {160, 120};
  fg.mask = cv::Mat::zeros(fg.frame_size, CV_8U);
  fg.mask(along).setTo(255);
  fg.mask(across).setTo(255);
  tracking::MotionDetectorParams p;
  const auto boxes = [&](cv::Vec2f across_motion) {
    fg.motion = cv::Mat(fg.frame_size, CV_32FC2, cv::Scalar(0, 0));
    fg.motion(along).setTo(cv::Scalar(3, 0));
    fg.motion(across).setTo(cv::Scalar(across_motion[0], across_motion[1]));
    return tracking::detect_objects(fg, p);
  };
  const std::vector<tracking::Detection> two = boxes({0, -3});
  ASSERT_EQ(two.size(), 2u);
  for (const cv::Rect& truth : {along, across}) {
    double best = 0;
    for (const tracking::Detection& d : two)
      best = std::max(best, test::box_iou(d.box, cv::Rect2f(truth)));
    EXPECT_GT(best, 0.9) << truth;
  }
  EXPECT_EQ(boxes({3, 0}).size(), 1u);
  fg.motion.release();
  EXPECT_EQ(tracking::detect_objects(fg, p).size(), 1u);
}

TEST(MotionDetector, RejectsBadSceneStartFlow) {
  for (const auto& bad : std::vector<void (*)(tracking::MotionDetectorParams&)>{
           [](tracking::MotionDetectorParams& p) { p.start_motion = -1; },
           [](tracking::MotionDetectorParams& p) { p.start_reach = -1; },
           [](tracking::MotionDetectorParams& p) { p.start_texture = 1000; }}) {
    tracking::MotionDetectorParams p;
    bad(p);
    EXPECT_THROW(p.validate(), Error);
  }
  tracking::MotionDetector detector;
  const cv::Mat frame(120, 160, CV_8UC3, cv::Scalar::all(90));
  detector.observe(frame);
  ASSERT_TRUE(detector.wants_flow());
  flow::FlowResult wrong;
  wrong.flow = cv::Mat(60, 80, CV_32FC2, cv::Scalar(0, 0));
  wrong.confidence = cv::Mat(60, 80, CV_32F, cv::Scalar(1));
  EXPECT_THROW(detector.observe(frame, &wrong), Error);
}

}  // namespace
}  // namespace roiflow
