// Shadows that are part of an object (tracking/shadow_parts.hpp): a shadow part the foreground
// surrounds becomes foreground, a cast shadow beside its object stays a shadow; and the motion
// detector's mask holds a grey body between bright parts only with the rule on.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "core/error.hpp"
#include "test_util.hpp"
#include "tracking/motion_detector.hpp"
#include "tracking/shadow_parts.hpp"

namespace roiflow::tracking {
namespace {

cv::Mat blank() {
  return cv::Mat(240, 320, CV_8U, cv::Scalar(0));
}

int count_of(const cv::Mat& labels, cv::Rect r, unsigned char value) {
  return cv::countNonZero(labels(r) == value);
}

TEST(ShadowParts, AnEnclosedBodyIsForegroundACastShadowIsNot) {
  cv::Mat labels = blank();
  labels(cv::Rect(100, 100, 40, 30)).setTo(kForegroundLabel);  // a car's bright outline
  const cv::Rect body(104, 104, 32, 22);
  labels(body).setTo(kShadowLabel);
  const cv::Rect cast(140, 100, 30, 30);  // its shadow, touching it along one side
  labels(cast).setTo(kShadowLabel);
  const cv::Rect alone(20, 20, 30, 20);  // a shadow with no object near it
  labels(alone).setTo(kShadowLabel);
  EXPECT_EQ(reclaim_enclosed_shadows(labels, 0.7), 1);
  EXPECT_EQ(count_of(labels, body, kForegroundLabel), body.area());
  EXPECT_EQ(count_of(labels, cast, kShadowLabel), cast.area());
  EXPECT_EQ(count_of(labels, alone, kShadowLabel), alone.area());
  EXPECT_EQ(cv::countNonZero(labels == 0), 320 * 240 - 40 * 30 - cast.area() - alone.area());
}

TEST(ShadowParts, TheShareOfTheOutlineDecides) {
  // A grey body with bright parts above, left and right, open below: three quarters of its
  // outline (less the corners) touch the foreground.
  auto scene = [] {
    cv::Mat labels = blank();
    labels(cv::Rect(100, 100, 44, 4)).setTo(kForegroundLabel);
    labels(cv::Rect(100, 104, 4, 40)).setTo(kForegroundLabel);
    labels(cv::Rect(140, 104, 4, 40)).setTo(kForegroundLabel);
    labels(cv::Rect(104, 104, 36, 40)).setTo(kShadowLabel);
    return labels;
  };
  cv::Mat open_below = scene();
  EXPECT_EQ(reclaim_enclosed_shadows(open_below, 0.7), 1);
  cv::Mat strict = scene();
  EXPECT_EQ(reclaim_enclosed_shadows(strict, 0.9), 0);
  EXPECT_EQ(count_of(strict, cv::Rect(104, 104, 36, 40), kShadowLabel), 36 * 40);
  // Two parts, each judged on its own outline: the body is reclaimed, a shadow cast from the
  // object's lower corner (touching it at one pixel) is not.
  cv::Mat two = scene();
  const cv::Rect corner(144, 144, 30, 10);
  two(corner).setTo(kShadowLabel);
  EXPECT_EQ(reclaim_enclosed_shadows(two, 0.7), 1);
  EXPECT_EQ(count_of(two, cv::Rect(104, 104, 36, 40), kForegroundLabel), 36 * 40);
  EXPECT_EQ(count_of(two, corner, kShadowLabel), corner.area());
}

TEST(ShadowParts, BadInputIsRefused) {
  cv::Mat floats(10, 10, CV_32F, cv::Scalar(0));
  EXPECT_NE(test::error_message([&] { reclaim_enclosed_shadows(floats, 0.5); }).find("8-bit"),
            std::string::npos);
  cv::Mat labels = blank();
  EXPECT_NE(test::error_message([&] { reclaim_enclosed_shadows(labels, 0); }).find("share"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { reclaim_enclosed_shadows(labels, 1.5); }).find("share"),
            std::string::npos);
  MotionDetectorParams p;
  p.shadow_enclosed = -0.1;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("shadow_enclosed"), std::string::npos);
}

// A fixed grey background; a grey object darker than it (the ratio MOG2 calls a shadow) with a
// bright top and bright sides, moving right. The detector's mask holds its body only with the
// rule on.
double body_share(double enclosed) {
  MotionDetectorParams p;
  p.shadow_enclosed = enclosed;
  p.work_width = 0;
  p.start_frames = 0;
  p.ghost_frames = 0;
  p.open = 0;
  MotionDetector detector(p);
  cv::RNG rng(7);
  Foreground fg;
  cv::Rect body;
  for (int t = 0; t < 60; ++t) {
    cv::Mat gray(240, 320, CV_8U);
    rng.fill(gray, cv::RNG::UNIFORM, 148, 153);
    if (t >= 40) {
      const int x = 60 + 3 * (t - 40);
      gray(cv::Rect(x, 100, 48, 40)).setTo(230);  // bright roof and sides
      body = cv::Rect(x + 6, 106, 36, 34);
      gray(body).setTo(100);  // grey body: 2/3 of the background's level
    }
    cv::Mat bgr;
    cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
    fg = detector.observe(bgr);
  }
  return fg.moving_share(cv::Rect2f(body));
}

TEST(ShadowParts, TheDetectorsMaskHoldsAGreyBodyBetweenBrightParts) {
  const double with_rule = body_share(0.7), without = body_share(0);
  EXPECT_GT(with_rule, 0.9);
  EXPECT_LT(without, 0.2);  // (the model labels the body a shadow)
}

}  // namespace
}  // namespace roiflow::tracking
