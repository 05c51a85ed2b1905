#include "tracking/camera_motion.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "eval/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::tracking {
namespace {

using test::error_message;

TEST(CameraShift, MeasuresAWholeFrameTranslation) {
  for (const cv::Point2f motion :
       {cv::Point2f(-31.f, 2.5f), cv::Point2f(12.f, -18.f), cv::Point2f(0.f, 0.f)}) {
    const eval::Scene s = eval::make_translation({320, 240}, motion, 5);
    const std::optional<cv::Point2f> g = camera_shift(s.frame0, s.frame1);
    ASSERT_TRUE(g.has_value());
    EXPECT_NEAR(g->x, motion.x, 1.0) << motion;
    EXPECT_NEAR(g->y, motion.y, 1.0) << motion;
  }
}

TEST(CameraShift, TheBackgroundWinsOverASmallMovingObject) {
  // The picture moves by (-20, 6); a 30x60 object pasted on it moves the other way.
  const eval::Scene s = eval::make_translation({640, 360}, {-20.f, 6.f}, 7);
  const cv::Mat object = eval::make_translation({30, 60}, {0.f, 0.f}, 8).frame0;
  cv::Mat a = s.frame0.clone(), b = s.frame1.clone();
  object.copyTo(a(cv::Rect(300, 150, 30, 60)));
  object.copyTo(b(cv::Rect(325, 140, 30, 60)));
  const std::optional<cv::Point2f> g = camera_shift(a, b);
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(g->x, -20.f, 1.5);
  EXPECT_NEAR(g->y, 6.f, 1.5);
}

TEST(CameraShift, AnExcludedObjectTakesNoPartOnAFlatBackground) {
  // A textured object jumps on a background with little texture: it would be the peak, unless
  // its box is left out.
  const eval::Scene s = eval::make_translation({320, 240}, {3.f, -2.f}, 11);
  cv::Mat a, b;
  cv::addWeighted(s.frame0, 0.15, cv::Mat(240, 320, CV_8UC1, cv::Scalar(100)), 0.85, 0, a);
  cv::addWeighted(s.frame1, 0.15, cv::Mat(240, 320, CV_8UC1, cv::Scalar(100)), 0.85, 0, b);
  const cv::Mat object = eval::make_translation({56, 36}, {0.f, 0.f}, 12).frame0;
  object.copyTo(a(cv::Rect(100, 100, 56, 36)));
  object.copyTo(b(cv::Rect(160, 100, 56, 36)));
  const std::optional<cv::Point2f> with = camera_shift(a, b);
  ASSERT_TRUE(with.has_value());
  EXPECT_NEAR(with->x, 60.f, 1.5);  // the object's jump
  const std::optional<cv::Point2f> without = camera_shift(a, b, cv::Rect2f(100, 100, 56, 36));
  ASSERT_TRUE(without.has_value());
  EXPECT_NEAR(without->x, 3.f, 1.5);
  EXPECT_NEAR(without->y, -2.f, 1.5);
}

TEST(CameraShift, NothingToTellOnAFlatPictureAndBadInput) {
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(90));
  EXPECT_FALSE(camera_shift(flat, flat).has_value());
  const cv::Mat tiny(6, 6, CV_8UC1, cv::Scalar(1));
  EXPECT_FALSE(camera_shift(tiny, tiny).has_value());
  EXPECT_NE(error_message([&] { camera_shift(flat, cv::Mat(120, 160, CV_8UC1)); }).find("one size"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              camera_shift(flat, flat, {}, {8, 0.05});
            }).find("work_width"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::tracking
