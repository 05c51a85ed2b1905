#include "eval/tracking_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "test_util.hpp"

namespace roiflow::eval {
namespace {

using test::error_message;

float centre_step(const cv::Rect2f& a, const cv::Rect2f& b) {
  const cv::Point2f d = (b.tl() + b.br()) * 0.5f - (a.tl() + a.br()) * 0.5f;
  return std::hypot(d.x, d.y);
}

TEST(TrackingScene, DefaultsAreTheDocumentedOnes) {
  const TrackingScene scene;
  EXPECT_EQ(scene.size(), cv::Size(640, 480));
  EXPECT_EQ(scene.frames(), 150);
  EXPECT_EQ(scene.jump_frame(), 75);
  const cv::Mat frame = scene.render(0);
  EXPECT_EQ(frame.type(), CV_8UC3);
  EXPECT_EQ(frame.size(), cv::Size(640, 480));
}

TEST(TrackingScene, IsDeterministicAndDependsOnTheSeed) {
  const TrackingScene a, b;
  for (int i : {0, 37, 75, 149}) {
    EXPECT_EQ(cv::norm(a.render(i), b.render(i), cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_EQ(a.box(i), b.box(i));
  }
  TrackingSceneParams other;
  other.seed = 2;
  EXPECT_GT(cv::norm(a.render(10), TrackingScene(other).render(10), cv::NORM_L1), 0.0);
  // Camera noise differs between frames even where nothing moves.
  const cv::Rect corner(0, 0, 40, 40);
  EXPECT_GT(cv::norm(a.render(1)(corner), a.render(2)(corner), cv::NORM_L1), 0.0);
}

TEST(TrackingScene, BoxesStayInsideTheFrame) {
  for (double scale : {-0.3, 0.0, 0.15, 0.6}) {
    TrackingSceneParams p;
    p.scale_change = scale;
    p.size = cv::Size(320, 240);
    p.object = cv::Size2f(40, 26);
    p.frames = 60;
    const TrackingScene scene(p);
    const cv::Rect2f frame(0, 0, 320, 240);
    for (int i = 0; i < scene.frames(); ++i) {
      const cv::Rect2f b = scene.box(i);
      EXPECT_EQ(b & frame, b) << "frame " << i << " scale " << scale;
      EXPECT_GT(b.area(), 0.f);
    }
    EXPECT_NEAR(scene.box(p.frames - 1).width / scene.box(0).width, 1.0 + scale, 1e-4);
  }
}

TEST(TrackingScene, HasOneJumpTooFastForA50PixelRegion) {
  const TrackingScene scene;
  const int j = scene.jump_frame();
  EXPECT_GT(centre_step(scene.box(j - 1), scene.box(j)), 40.f);
  float fastest_other = 0, slowest = 1e9f;
  for (int i = 1; i < scene.frames(); ++i) {
    if (i == j) continue;
    const float step = centre_step(scene.box(i - 1), scene.box(i));
    fastest_other = std::max(fastest_other, step);
    slowest = std::min(slowest, step);
  }
  EXPECT_LT(fastest_other, 12.f);
  // The speed changes: the vehicle accelerates and brakes.
  EXPECT_GT(fastest_other, 2.5f * slowest);

  TrackingSceneParams p;
  p.jump_frame = 20;
  p.jump = 60;
  const TrackingScene moved(p);
  EXPECT_EQ(moved.jump_frame(), 20);
  EXPECT_NEAR(moved.box(20).x - moved.box(19).x, 60.f, 1e-3);
}

TEST(TrackingScene, VehicleDiffersFromTheBackgroundInsideItsBox) {
  TrackingSceneParams p;
  p.noise = 0;
  const TrackingScene scene(p);
  for (int i : {0, 80, 149}) {
    const cv::Rect2f b = scene.box(i);
    // The inner part of the box (clear of the rounded corners) is vehicle, not background.
    const cv::Rect inner(
        cv::Point(static_cast<int>(b.x + 0.25f * b.width),
                  static_cast<int>(b.y + 0.25f * b.height)),
        cv::Size(static_cast<int>(0.5f * b.width), static_cast<int>(0.5f * b.height)));
    cv::Mat diff;
    cv::absdiff(scene.render(i)(inner), scene.background()(inner), diff);
    EXPECT_GT(cv::mean(diff)[2], 40.0) << "frame " << i;
    // Outside the box (two pixels away) the frame is the background.
    const cv::Rect outside(static_cast<int>(b.x + b.width) + 2, static_cast<int>(b.y), 10,
                           static_cast<int>(b.height));
    if ((outside & cv::Rect(cv::Point(), scene.size())) == outside) {
      EXPECT_EQ(cv::norm(scene.render(i)(outside), scene.background()(outside), cv::NORM_INF), 0.0);
    }
    // The vehicle has texture of its own for Lucas-Kanade to lock on.
    cv::Mat gray;
    cv::cvtColor(scene.render(i)(inner), gray, cv::COLOR_BGR2GRAY);
    cv::Scalar mean, stddev;
    cv::meanStdDev(gray, mean, stddev);
    EXPECT_GT(stddev[0], 8.0);
  }
}

TEST(TrackingScene, ObjectEdgeIsWhereTheBoxSays) {
  TrackingSceneParams p;
  p.noise = 0;
  p.jump = 0;
  const TrackingScene scene(p);
  const cv::Rect2f b = scene.box(40);
  cv::Mat diff;
  cv::absdiff(scene.render(40), scene.background(), diff);
  cv::Mat gray;
  cv::cvtColor(diff, gray, cv::COLOR_BGR2GRAY);
  cv::Mat mask = gray > 20;
  const cv::Rect found = cv::boundingRect(mask);
  EXPECT_NEAR(found.x, b.x, 1.5);
  EXPECT_NEAR(found.y, b.y, 1.5);
  EXPECT_NEAR(found.br().x, b.br().x, 1.5);
  EXPECT_NEAR(found.br().y, b.br().y, 1.5);
}

TEST(TrackingScene, BadParamsAndIndicesThrowNamingTheValue) {
  TrackingSceneParams p;
  p.frames = 2;
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("2"), std::string::npos);
  p = {};
  p.jump_frame = 150;
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("150"), std::string::npos);
  p = {};
  p.scale_change = -0.7;
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("-0.7"), std::string::npos);
  p = {};
  p.object = cv::Size2f(300, 40);
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("300"), std::string::npos);
  p = {};
  p.jump = -3;
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("-3"), std::string::npos);
  p = {};
  p.size = cv::Size(20, 480);
  EXPECT_NE(error_message([&] { TrackingScene{p}; }).find("20x480"), std::string::npos);
  const TrackingScene scene;
  EXPECT_NE(error_message([&] { scene.render(150); }).find("150"), std::string::npos);
  EXPECT_NE(error_message([&] { scene.box(-1); }).find("-1"), std::string::npos);
}

}  // namespace
}  // namespace roiflow::eval
