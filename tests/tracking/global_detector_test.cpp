#include "tracking/global_detector.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "eval/otb_score.hpp"
#include "eval/tracking_scene.hpp"
#include "test_util.hpp"

namespace roiflow::tracking {
namespace {

using eval::TrackingScene;
using eval::TrackingSceneParams;
using test::error_message;

cv::Mat gray_image(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// A second mover for the two-object scenes: a blue-green textured block, larger
// than the scene's red vehicle, moving right to left along the bottom of the
// frame.
cv::Rect2f draw_decoy(cv::Mat& frame, int i) {
  const cv::Rect box(540 - 4 * i, 360, 90, 56);
  cv::Mat block(box.size(), CV_8UC3, cv::Scalar(130, 110, 0));
  cv::Mat texture(box.size(), CV_8UC3);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 120);
  block += texture;
  block.copyTo(frame(box));
  return box;
}

const Detection* overlapping(const std::vector<Detection>& objects, const cv::Rect2f& truth) {
  for (const Detection& d : objects) {
    if (eval::iou(d.box, truth) > 0.5) return &d;
  }
  return nullptr;
}

TEST(GlobalDetector, FindsTheMovingVehicleAfterWarmup) {
  for (bool gray : {false, true}) {
    SCOPED_TRACE(gray ? "gray" : "BGR");
    const TrackingScene scene;
    GlobalDetectorParams params;
    params.warmup = 5;
    GlobalDetector detector(params);
    int found = 0;
    for (int i = 0; i < 70; ++i) {
      const cv::Mat frame = gray ? gray_image(scene.render(i)) : scene.render(i);
      detector.observe(frame);
      const std::vector<Detection> objects = detector.moving_objects();
      if (i < params.warmup) {
        EXPECT_TRUE(objects.empty()) << "frame " << i;
        continue;
      }
      for (std::size_t k = 1; k < objects.size(); ++k) {
        EXPECT_GE(objects[k - 1].score, objects[k].score) << "frame " << i;
      }
      if (i < 20) continue;  // the vehicle's first position is still a ghost in the model
      ASSERT_FALSE(objects.empty()) << "frame " << i;
      const cv::Rect2f truth = scene.box(i);
      const cv::Point2f centre = (truth.tl() + truth.br()) * 0.5f;
      found +=
          eval::iou(objects[0].box, truth) > 0.75 && cv::norm(objects[0].barycentre - centre) < 6.0;
    }
    // Where the vehicle slows down to ~1 pixel a frame (frames 40-48) the model learns parts
    // of it; in gray, where it contrasts less, more so.
    EXPECT_GE(found, gray ? 18 : 45) << "of 50";
  }
}

TEST(GlobalDetector, FindsNothingInAStaticScene) {
  const TrackingScene scene;
  GlobalDetectorParams params;
  params.warmup = 3;
  GlobalDetector detector(params);
  cv::RNG rng(3);
  for (int i = 0; i < 40; ++i) {
    cv::Mat noise(scene.size(), CV_16SC3);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
    cv::Mat frame;
    cv::add(scene.background(), noise, frame, cv::noArray(), CV_8UC3);
    detector.observe(frame);
    EXPECT_TRUE(detector.moving_objects().empty()) << "frame " << i;
  }
}

TEST(GlobalDetector, SmallObjectsAreNoise) {
  const TrackingScene scene;
  GlobalDetectorParams params;
  params.min_area = 1.2 * scene.box(40).area();  // the vehicle is smaller than this
  GlobalDetector detector(params);
  for (int i = 0; i <= 40; ++i)
    detector.observe(scene.render(i));
  EXPECT_TRUE(detector.moving_objects().empty());
}

TEST(GlobalDetector, ReDetectsByAppearanceAnywhereAtAnotherScale) {
  TrackingSceneParams p;
  p.scale_change = 0.25;
  const TrackingScene scene(p);
  for (bool gray : {false, true}) {
    SCOPED_TRACE(gray ? "gray" : "BGR");
    GlobalDetector detector;
    EXPECT_FALSE(detector.has_target());
    const cv::Mat first = scene.render(5);
    detector.set_target(gray ? gray_image(first) : first, scene.box(5));
    ASSERT_TRUE(detector.has_target());
    EXPECT_EQ(detector.target_size(), cv::Size2f(scene.box(5).size()));
    // Far to the right and 22 % larger; the search knows nothing of where.
    const int later = p.frames - 5;
    const cv::Mat frame = scene.render(later);
    const auto found = gray ? detector.find_target(gray_image(frame), {}, {0, 0}, true)
                            : detector.find_target(frame, {}, {0, 0}, true);
    ASSERT_TRUE(found.has_value());
    EXPECT_GT(eval::iou(found->box, scene.box(later)), 0.8);
    EXPECT_GT(found->score, 0.7);
    EXPECT_LE(found->score, 1.0);
    // The gray frame may be given alongside, as the pipeline has it anyway.
    const auto again = detector.find_target(frame, gray_image(frame), {0, 0}, true);
    ASSERT_TRUE(again.has_value());
    EXPECT_NEAR(again->box.x, found->box.x, 0.01);
  }
}

TEST(GlobalDetector, SetTargetSizeSteersTheAppearanceScales) {
  TrackingSceneParams p;
  p.scale_change = 0.8;
  p.object = cv::Size2f(60, 36);
  const TrackingScene scene(p);
  GlobalDetector detector;
  detector.set_target(scene.render(0), scene.box(0));
  const int later = p.frames - 1;  // 1.8 times the size: beyond the scales around the template
  detector.set_target_size(scene.box(later).size());
  EXPECT_EQ(detector.target_size(), scene.box(later).size());
  const auto found = detector.find_target(scene.render(later), {}, {}, true);
  ASSERT_TRUE(found.has_value());
  EXPECT_GT(eval::iou(found->box, scene.box(later)), 0.7);
}

TEST(GlobalDetector, NothingFoundWithoutTargetOrWhenTheTargetIsAbsent) {
  const TrackingScene scene;
  GlobalDetector detector;
  EXPECT_FALSE(detector.find_target(scene.render(10), {}, {}, true).has_value());
  EXPECT_FALSE(detector.find_target(scene.render(10), {}, {}, false).has_value());
  GlobalDetectorParams params;
  params.min_score = 0.8;
  GlobalDetector strict(params);
  strict.set_target(scene.render(10), scene.box(10));
  EXPECT_FALSE(strict.find_target(scene.background(), {}, {}, true).has_value());
}

TEST(GlobalDetector, SignaturePicksTheTargetAmongTwoMovers) {
  for (bool gray : {false, true}) {
    SCOPED_TRACE(gray ? "gray" : "BGR");
    const TrackingScene scene;
    GlobalDetector detector;
    const auto frame_at = [&](int i) {
      cv::Mat f = scene.render(i);
      draw_decoy(f, i);
      return gray ? gray_image(f) : f;
    };
    for (int i = 0; i <= 30; ++i)
      detector.observe(frame_at(i));
    const std::vector<Detection> objects = detector.moving_objects();
    ASSERT_GE(objects.size(), 2u);  // in gray, a fragment of the vehicle may be a third
    cv::Mat scratch(scene.size(), CV_8UC3);
    EXPECT_NE(overlapping(objects, draw_decoy(scratch, 30)), nullptr);
    const Detection* vehicle = overlapping(objects, scene.box(30));
    ASSERT_NE(vehicle, nullptr);
    detector.set_target(frame_at(30), vehicle->box);

    for (int i = 31; i <= 60; ++i)
      detector.observe(frame_at(i));
    // `near` points at the decoy: similarity must win over position.
    const cv::Rect2f decoy = draw_decoy(scratch, 60);
    const auto found =
        detector.find_target(frame_at(60), {}, (decoy.tl() + decoy.br()) * 0.5f, false);
    ASSERT_TRUE(found.has_value());
    EXPECT_GT(eval::iou(found->box, scene.box(60)), 0.75);
    EXPECT_GE(found->score, 0.5);
    EXPECT_LE(found->score, 1.0);
  }
}

// The colour check of a re-detection: the target's own box matches its colours, a decoy of other
// colours does not, and a recoloured target (lighting, pose) matches once a look of it is kept.
TEST(GlobalDetector, ColourSimilarityTellsTheTargetFromADecoyAndKeepsRecentLooks) {
  const TrackingScene scene;
  cv::Mat frame = scene.render(30);
  const cv::Rect2f decoy = draw_decoy(frame, 30);
  GlobalDetector detector;
  EXPECT_EQ(detector.colour_similarity(frame, scene.box(30)), -1.0);  // no target yet
  detector.set_target(frame, scene.box(30));
  EXPECT_GT(detector.colour_similarity(frame, scene.box(30)), 0.95);
  EXPECT_LT(detector.colour_similarity(frame, decoy), 0.3);
  EXPECT_EQ(detector.colour_similarity(frame, cv::Rect2f(-50, -50, 20, 20)), -1.0);
  // The same frame with blue and red swapped: the vehicle changes hue.
  cv::Mat swapped;
  cv::cvtColor(frame, swapped, cv::COLOR_BGR2RGB);
  const double before = detector.colour_similarity(swapped, scene.box(30));
  EXPECT_LT(before, 0.4);  // measured: 0.11 (the decoy 0.07)
  detector.remember_colour(swapped, scene.box(30));
  EXPECT_GT(detector.colour_similarity(swapped, scene.box(30)), 0.95);
  EXPECT_GT(detector.colour_similarity(frame, scene.box(30)), 0.95);  // the first look stays
  // set_target forgets the remembered looks.
  detector.set_target(frame, scene.box(30));
  EXPECT_NEAR(detector.colour_similarity(swapped, scene.box(30)), before, 1e-9);
}

TEST(GlobalDetector, NearBreaksTiesBetweenTwins) {
  // Two identical vehicles (the scene's and a copy moving the other way, higher up): the
  // one nearest to `near` wins.
  const TrackingScene scene;
  GlobalDetector detector;
  const auto frame_at = [&](int i) {
    cv::Mat f = scene.render(i);
    const cv::Rect2f b = scene.box(i);
    const cv::Rect src(cv::Point(static_cast<int>(b.x), static_cast<int>(b.y)),
                       cv::Size(static_cast<int>(b.width), static_cast<int>(b.height)));
    const cv::Rect dst(cv::Point(f.cols - src.br().x, src.y - 150), src.size());
    f(src).copyTo(f(dst));
    return f;
  };
  for (int i = 0; i <= 40; ++i)
    detector.observe(frame_at(i));
  detector.set_target(frame_at(40), scene.box(40));
  for (int i = 41; i <= 50; ++i)
    detector.observe(frame_at(i));
  const cv::Rect2f b = scene.box(50);
  const cv::Point2f centre = (b.tl() + b.br()) * 0.5f;
  const cv::Point2f twin(static_cast<float>(scene.size().width) - centre.x, centre.y - 150);
  const auto at_vehicle = detector.find_target(frame_at(50), {}, centre, false);
  const auto at_twin = detector.find_target(frame_at(50), {}, twin, false);
  ASSERT_TRUE(at_vehicle.has_value());
  ASSERT_TRUE(at_twin.has_value());
  EXPECT_LT(cv::norm(at_vehicle->barycentre - centre), 10.0);
  EXPECT_LT(cv::norm(at_twin->barycentre - twin), 10.0);
}

TEST(GlobalDetector, BadParamsThrowNamingTheValue) {
  const auto message = [](auto change) {
    GlobalDetectorParams p;
    change(p);
    return error_message([&] { GlobalDetector{p}; });
  };
  EXPECT_NE(message([](auto& p) { p.history = 1; }).find("history must be >= 2, got 1"),
            std::string::npos);
  EXPECT_NE(message([](auto& p) { p.warmup = -4; }).find("-4"), std::string::npos);
  EXPECT_NE(message([](auto& p) { p.work_width = -320; }).find("-320"), std::string::npos);
  EXPECT_NE(message([](auto& p) { p.min_area = -9; }).find("-9"), std::string::npos);
  EXPECT_NE(message([](auto& p) { p.min_score = 1.5; }).find("1.5"), std::string::npos);
  EXPECT_NE(message([](auto& p) { p.min_score = 0; }).find("min_score"), std::string::npos);
  EXPECT_NE(message([](auto& p) {
              p.appearance_scales = {1.0, -0.25};
            }).find("-0.25"),
            std::string::npos);
  EXPECT_NE(message([](auto& p) { p.appearance_scales.clear(); }).find("empty"), std::string::npos);
  EXPECT_EQ(message([](auto&) {}), "no exception");
}

TEST(GlobalDetector, BadInputsThrowNamingTheValue) {
  GlobalDetector detector;
  EXPECT_NE(error_message([&] { detector.observe(cv::Mat(48, 64, CV_16UC1)); }).find("16UC1"),
            std::string::npos);
  EXPECT_NE(error_message([&] { detector.observe(cv::Mat()); }).find("empty"), std::string::npos);
  detector.observe(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0)));
  EXPECT_NE(error_message([&] { detector.observe(cv::Mat(48, 60, CV_8UC3)); }).find("60x48"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              detector.observe(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0)), 0.0);
            }).find("weight"),
            std::string::npos);
  const cv::Mat frame(48, 64, CV_8UC3, cv::Scalar::all(90));
  EXPECT_NE(error_message([&] {
              detector.set_target(frame, {70, 10, 20, 20});
            }).find("70"),
            std::string::npos);
  EXPECT_FALSE(detector.has_target());
  detector.set_target(frame, {10, 10, 20, 20});
  EXPECT_NE(error_message([&] {
              detector.set_target_size({0, 5});
            }).find("0 x 5"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              detector.find_target(cv::Mat(48, 64, CV_8UC1), {}, {}, false);
            }).find("3-channel"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              detector.find_target(frame, cv::Mat(48, 64, CV_32FC1), {}, true);
            }).find("32FC1"),
            std::string::npos);
}

// An observation that stands for many frames learns as much as they would: a block that
// appears and stays is learnt into the background after a few heavy observations, while as
// many plain ones still see it as a moving object.
TEST(GlobalDetector, AHeavierObservationLearnsFaster) {
  cv::Mat background(240, 320, CV_8UC3);
  cv::RNG rng(11);
  rng.fill(background, cv::RNG::UNIFORM, 40, 200);
  cv::Mat with_block = background.clone();
  with_block(cv::Rect(120, 80, 60, 50)).setTo(cv::Scalar(20, 220, 240));
  for (double weight : {1.0, 20.0}) {
    GlobalDetectorParams params;
    params.warmup = 2;
    GlobalDetector detector(params);
    for (int i = 0; i < 10; ++i)
      detector.observe(background);
    for (int i = 0; i < 6; ++i)
      detector.observe(with_block, weight);
    EXPECT_EQ(detector.moving_objects().empty(), weight > 1.0) << "weight " << weight;
  }
}

}  // namespace
}  // namespace roiflow::tracking
