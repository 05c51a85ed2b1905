#include "eval/synthetic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/error.hpp"

namespace roiflow::eval {
namespace {

constexpr SceneKind kAllKinds[] = {SceneKind::Translation, SceneKind::Rotation, SceneKind::Zoom,
                                   SceneKind::NonRigid, SceneKind::MovingObject};
const cv::Size kSceneSize(320, 240);
// For properties that do not need the full size: keeps the suite quick in Debug builds.
const cv::Size kSmall(160, 120);

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// frame1 sampled at x + gt(x): equals frame0 wherever the ground truth is right, up to
// quantisation and bilinear interpolation. Float, so remap adds no rounding of its own.
cv::Mat warp_back(const cv::Mat& frame1, const cv::Mat& flow) {
  cv::Mat map(flow.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f d = flow.at<cv::Vec2f>(y, x);
      map.at<cv::Vec2f>(y, x) = cv::Vec2f(x + d[0], y + d[1]);
    }
  }
  cv::Mat source, warped;
  frame1.convertTo(source, CV_32F);
  cv::remap(source, warped, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return warped;
}

double mean_abs_difference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat fa, fb, diff;
  a.convertTo(fa, CV_32F);
  b.convertTo(fb, CV_32F);
  cv::absdiff(fa, fb, diff);
  return cv::mean(diff, mask)[0];
}

// Pixels that the check may use: a 10 px border is left out (content enters there), and for
// the moving object a 3 px band around the object in both frames and the background it
// covers in frame1 (occluded: no correspondence exists).
cv::Mat check_mask(const Scene& scene, SceneKind kind) {
  cv::Mat mask(scene.flow.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect interior(10, 10, mask.cols - 20, mask.rows - 20);
  mask(interior).setTo(255);
  if (kind != SceneKind::MovingObject) return mask;

  cv::Mat object(scene.flow.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < object.rows; ++y) {
    for (int x = 0; x < object.cols; ++x) {
      const cv::Vec2f d = scene.flow.at<cv::Vec2f>(y, x);
      if (std::abs(d[0] - 3.2f) < 1e-4f && std::abs(d[1] - 1.5f) < 1e-4f)
        object.at<uchar>(y, x) = 1;
    }
  }
  const cv::Rect r0 = cv::boundingRect(object);
  const cv::Rect r1 = r0 + cv::Point(4, 2);  // moved by (3.2, 1.5), rounded up
  const cv::Rect both = r0 | r1;
  const cv::Rect band(both.x - 3, both.y - 3, both.width + 6, both.height + 6);
  mask(band & interior).setTo(0);
  const cv::Rect object_core(r0.x + 3, r0.y + 3, r0.width - 6, r0.height - 6);
  mask(object_core & interior).setTo(255);
  return mask;
}

class SceneTest : public testing::TestWithParam<SceneKind> {};

TEST_P(SceneTest, HasRequestedSizeAndTypes) {
  for (const cv::Size size : {kSmall, cv::Size(37, 29), cv::Size(8, 8)}) {
    const Scene s = make_scene(GetParam(), size, 3);
    EXPECT_EQ(s.frame0.size(), size);
    EXPECT_EQ(s.frame1.size(), size);
    EXPECT_EQ(s.flow.size(), size);
    EXPECT_EQ(s.frame0.type(), CV_8UC1);
    EXPECT_EQ(s.frame1.type(), CV_8UC1);
    EXPECT_EQ(s.flow.type(), CV_32FC2);
  }
}

TEST_P(SceneTest, IsDeterministicForASeed) {
  const Scene a = make_scene(GetParam(), kSmall, 11);
  const Scene b = make_scene(GetParam(), kSmall, 11);
  const Scene c = make_scene(GetParam(), kSmall, 12);
  EXPECT_TRUE(identical(a.frame0, b.frame0));
  EXPECT_TRUE(identical(a.frame1, b.frame1));
  EXPECT_TRUE(identical(a.flow, b.flow));
  EXPECT_FALSE(identical(a.frame0, c.frame0));
  EXPECT_FALSE(identical(a.frame1, c.frame1));
}

TEST_P(SceneTest, TextureHasContrastWithoutSaturation) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    const Scene s = make_scene(GetParam(), kSmall, seed);
    for (const cv::Mat* frame : {&s.frame0, &s.frame1}) {
      cv::Scalar mean, stddev;
      cv::meanStdDev(*frame, mean, stddev);
      double lo = 0, hi = 0;
      cv::minMaxLoc(*frame, &lo, &hi);
      EXPECT_GT(stddev[0], 0.1 * 255) << "seed " << seed;
      EXPECT_GE(lo, 12) << "seed " << seed;
      EXPECT_LE(hi, 243) << "seed " << seed;
    }
  }
}

// The ground truth is physically right: frame1 pulled back along it matches frame0 far
// better than frame1 itself does, and to within about one grey level.
TEST_P(SceneTest, GroundTruthAlignsTheFrames) {
  for (const std::uint64_t seed : {1, 7}) {
    const Scene s = make_scene(GetParam(), kSceneSize, seed);
    const cv::Mat mask = check_mask(s, GetParam());
    ASSERT_GT(cv::countNonZero(mask), kSceneSize.area() / 2);
    const double unaligned = mean_abs_difference(s.frame0, s.frame1, mask);
    const double aligned = mean_abs_difference(s.frame0, warp_back(s.frame1, s.flow), mask);
    RecordProperty("unaligned_seed" + std::to_string(seed), std::to_string(unaligned));
    RecordProperty("aligned_seed" + std::to_string(seed), std::to_string(aligned));
    EXPECT_LT(aligned, 0.25 * unaligned) << "seed " << seed;
    EXPECT_LT(aligned, 1.5) << "seed " << seed << ", unaligned " << unaligned;
  }
}

INSTANTIATE_TEST_SUITE_P(AllKinds, SceneTest, testing::ValuesIn(kAllKinds),
                         [](const testing::TestParamInfo<SceneKind>& p) {
                           return std::string(to_string(p.param));
                         });

TEST(Synthetic, TranslationFlowIsTheDocumentedConstant) {
  const Scene s = make_scene(SceneKind::Translation, kSceneSize);
  cv::Mat channels[2];
  cv::split(s.flow, channels);
  EXPECT_EQ(cv::norm(channels[0] - 1.3f, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(channels[1] + 0.7f, cv::NORM_INF), 0);
}

TEST(Synthetic, RotationIsCounterClockwiseOnScreen) {
  const Scene s = make_scene(SceneKind::Rotation, kSceneSize);
  const double cx = (kSceneSize.width - 1) / 2.0, cy = (kSceneSize.height - 1) / 2.0;
  // A point 100 px right of the centre: y points down, so counter-clockwise moves it up.
  const int x = static_cast<int>(cx + 100.5), y = static_cast<int>(cy);
  const cv::Vec2f d = s.flow.at<cv::Vec2f>(y, x);
  const double theta = 3.0 * CV_PI / 180;
  const double rx = x - cx, ry = y - cy;
  EXPECT_LT(d[1], -5.0);
  EXPECT_NEAR(d[0], rx * std::cos(theta) + ry * std::sin(theta) - rx, 1e-4);
  EXPECT_NEAR(d[1], -rx * std::sin(theta) + ry * std::cos(theta) - ry, 1e-4);
}

TEST(Synthetic, ZoomFlowPointsAwayFromTheCentre) {
  const Scene s = make_scene(SceneKind::Zoom, kSceneSize);
  const double cx = (kSceneSize.width - 1) / 2.0, cy = (kSceneSize.height - 1) / 2.0;
  const cv::Vec2f d = s.flow.at<cv::Vec2f>(10, 300);
  EXPECT_NEAR(d[0], 0.04 * (300 - cx), 1e-4);
  EXPECT_NEAR(d[1], 0.04 * (10 - cy), 1e-4);
}

TEST(Synthetic, NonRigidFlowIsSmoothAndAboutTwoPixels) {
  const Scene s = make_scene(SceneKind::NonRigid, kSceneSize);
  cv::Mat channels[2];
  cv::split(s.flow, channels);
  for (const cv::Mat& c : channels) {
    double lo = 0, hi = 0;
    cv::minMaxLoc(c, &lo, &hi);
    EXPECT_GE(lo, -2.0);
    EXPECT_LE(hi, 2.0);
    EXPECT_GT(hi - lo, 1.0);  // not a translation in disguise
  }
  cv::Mat dx, dy;
  cv::Sobel(s.flow, dx, CV_32F, 1, 0, 1);
  cv::Sobel(s.flow, dy, CV_32F, 0, 1, 1);
  // Central differences span 2 px; a smooth field with |grad d| < 0.5 changes < 1 over that.
  EXPECT_LT(cv::norm(dx, cv::NORM_INF), 1.0);
  EXPECT_LT(cv::norm(dy, cv::NORM_INF), 1.0);
}

TEST(Synthetic, MovingObjectCoversAQuarterOfEachSideLeftOfCentre) {
  const Scene s = make_scene(SceneKind::MovingObject, kSceneSize);
  cv::Mat object(kSceneSize, CV_8UC1, cv::Scalar(0));
  int background = 0;
  for (int y = 0; y < kSceneSize.height; ++y) {
    for (int x = 0; x < kSceneSize.width; ++x) {
      const cv::Vec2f d = s.flow.at<cv::Vec2f>(y, x);
      if (d == cv::Vec2f(3.2f, 1.5f)) object.at<uchar>(y, x) = 1;
      if (d == cv::Vec2f(0.6f, 0.4f)) ++background;
    }
  }
  const cv::Rect r = cv::boundingRect(object);
  EXPECT_EQ(cv::countNonZero(object), r.area());  // a solid rectangle
  EXPECT_EQ(cv::countNonZero(object) + background, kSceneSize.area());
  EXPECT_NEAR(r.width, kSceneSize.width / 4, 1);
  EXPECT_NEAR(r.height, kSceneSize.height / 4, 1);
  EXPECT_LT(r.x + r.width / 2, kSceneSize.width / 2);
}

TEST(Synthetic, LargeTranslationIsExact) {
  const cv::Point2f motion(-17.25f, 9.5f);
  const Scene s = make_translation(kSceneSize, motion, 5);
  EXPECT_EQ(s.flow.at<cv::Vec2f>(100, 100), cv::Vec2f(motion.x, motion.y));
  cv::Mat mask(kSceneSize, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(30, 20, kSceneSize.width - 60, kSceneSize.height - 40)).setTo(255);
  const double unaligned = mean_abs_difference(s.frame0, s.frame1, mask);
  const double aligned = mean_abs_difference(s.frame0, warp_back(s.frame1, s.flow), mask);
  EXPECT_LT(aligned, 0.25 * unaligned);
  EXPECT_LT(aligned, 1.5);
}

TEST(Synthetic, BadArgumentsThrowNamingTheValue) {
  for (const cv::Size size : {cv::Size(7, 100), cv::Size(100, 7), cv::Size(8193, 10),
                              cv::Size(10, 8193), cv::Size(0, 0), cv::Size(-5, 20)}) {
    const std::string expected = std::to_string(size.width) + "x" + std::to_string(size.height);
    try {
      make_scene(SceneKind::Translation, size);
      ADD_FAILURE() << "no exception for " << expected;
    } catch (const roiflow::Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(make_translation(kSceneSize, cv::Point2f(NAN, 0)), roiflow::Error);
  try {
    make_translation(kSceneSize, cv::Point2f(0, 9000));
    ADD_FAILURE() << "no exception for a 9000 px motion";
  } catch (const roiflow::Error& e) {
    EXPECT_NE(std::string(e.what()).find("9000"), std::string::npos) << e.what();
  }
}

TEST(Synthetic, NamesAreStable) {
  EXPECT_STREQ(to_string(SceneKind::Translation), "translation");
  EXPECT_STREQ(to_string(SceneKind::Rotation), "rotation");
  EXPECT_STREQ(to_string(SceneKind::Zoom), "zoom");
  EXPECT_STREQ(to_string(SceneKind::NonRigid), "nonrigid");
  EXPECT_STREQ(to_string(SceneKind::MovingObject), "moving_object");
}

}  // namespace
}  // namespace roiflow::eval
