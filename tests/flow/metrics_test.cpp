#include "flow/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.hpp"

namespace roiflow::flow {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kUnknown = 1.6666668e9f;

double degrees(double radians) {
  return radians * 180.0 / std::numbers::pi;
}

cv::Mat one_pixel(float u, float v) {
  return cv::Mat(1, 1, CV_32FC2, cv::Scalar(u, v));
}

TEST(Metrics, KnownFlow) {
  EXPECT_TRUE(is_known_flow(0, 0));
  EXPECT_TRUE(is_known_flow(-1e9f, 1e9f));
  EXPECT_FALSE(is_known_flow(kUnknown, 0));
  EXPECT_FALSE(is_known_flow(0, -kUnknown));
  EXPECT_FALSE(is_known_flow(kNaN, 0));
  EXPECT_FALSE(is_known_flow(0, kNaN));
  EXPECT_FALSE(is_known_flow(kInf, 0));
  EXPECT_FALSE(is_known_flow(0, -kInf));
}

TEST(Metrics, UnitErrorIsFortyFiveDegreesAndNotOverOne) {
  const FlowErrors e = flow_errors(one_pixel(1, 0), one_pixel(0, 0));
  EXPECT_EQ(e.pixels, 1);
  EXPECT_DOUBLE_EQ(e.epe, 1.0);
  EXPECT_NEAR(e.aae_deg, 45.0, 1e-9);
  EXPECT_EQ(e.r1, 0.0);  // EPE exactly 1 is not > 1
  EXPECT_EQ(e.r3, 0.0);
}

TEST(Metrics, ThreeFourFive) {
  const FlowErrors e = flow_errors(one_pixel(3, 4), one_pixel(0, 0));
  EXPECT_DOUBLE_EQ(e.epe, 5.0);
  EXPECT_NEAR(e.aae_deg, degrees(std::acos(1 / std::sqrt(26.0))), 1e-9);
  EXPECT_EQ(e.r1, 100.0);
  EXPECT_EQ(e.r3, 100.0);
}

TEST(Metrics, EpeExactlyThreeIsNotOverThree) {
  const FlowErrors e = flow_errors(one_pixel(-2, 7), one_pixel(1, 7));
  EXPECT_DOUBLE_EQ(e.epe, 3.0);
  EXPECT_EQ(e.r1, 100.0);
  EXPECT_EQ(e.r3, 0.0);
}

TEST(Metrics, AngleUsesTheUnitThirdComponent) {
  // (1,0,1) vs (0,1,1): cos = 1 / 2, 60 degrees; the 2-D angle would be 90.
  const FlowErrors e = flow_errors(one_pixel(1, 0), one_pixel(0, 1));
  EXPECT_NEAR(e.aae_deg, 60.0, 1e-9);
  EXPECT_NEAR(e.epe, std::sqrt(2.0), 1e-12);
}

TEST(Metrics, PerfectEstimateIsZero) {
  cv::Mat gt(5, 7, CV_32FC2);
  cv::randu(gt, cv::Scalar::all(-20), cv::Scalar::all(20));
  const FlowErrors e = flow_errors(gt, gt);
  EXPECT_EQ(e.pixels, 35);
  EXPECT_EQ(e.epe, 0.0);
  EXPECT_NEAR(e.aae_deg, 0.0, 1e-4);  // acos near 1 amplifies rounding
  EXPECT_EQ(e.r1, 0.0);
}

// 3 wide, 2 high; the estimate is NaN only where the ground truth is unknown or excluded.
struct Mixed {
  cv::Mat estimate = cv::Mat(2, 3, CV_32FC2);
  cv::Mat ground_truth = cv::Mat(2, 3, CV_32FC2);
  cv::Mat exclude = cv::Mat(2, 3, CV_8UC1, cv::Scalar(0));
  Mixed() {
    auto set = [](cv::Mat& m, int x, int y, float u, float v) { m.at<cv::Vec2f>(y, x) = {u, v}; };
    set(ground_truth, 0, 0, 0, 0);
    set(estimate, 0, 0, 1, 0);  // EPE 1, 45 deg
    set(ground_truth, 1, 0, kUnknown, 0);
    set(estimate, 1, 0, kNaN, kNaN);  // not counted
    set(ground_truth, 2, 0, kNaN, kNaN);
    set(estimate, 2, 0, 5, 5);  // not counted
    set(ground_truth, 0, 1, 0, 0);
    set(estimate, 0, 1, 3, 4);  // EPE 5
    set(ground_truth, 1, 1, 0, 0);
    set(estimate, 1, 1, 0, 2);  // EPE 2, counted only without the mask
    set(ground_truth, 2, 1, 1, 1);
    set(estimate, 2, 1, 1, 1);  // EPE 0
    exclude.at<uchar>(1, 1) = 7;
  }
};

TEST(Metrics, SkipsUnknownAndExcludedPixels) {
  const Mixed m;
  const FlowErrors masked = flow_errors(m.estimate, m.ground_truth, m.exclude);
  EXPECT_EQ(masked.pixels, 3);
  EXPECT_DOUBLE_EQ(masked.epe, (1 + 5 + 0) / 3.0);
  EXPECT_NEAR(masked.aae_deg, (45 + degrees(std::acos(1 / std::sqrt(26.0)))) / 3, 1e-6);
  EXPECT_DOUBLE_EQ(masked.r1, 100.0 / 3);
  EXPECT_DOUBLE_EQ(masked.r3, 100.0 / 3);

  const FlowErrors all = flow_errors(m.estimate, m.ground_truth);
  EXPECT_EQ(all.pixels, 4);
  EXPECT_DOUBLE_EQ(all.epe, (1 + 5 + 2 + 0) / 4.0);
  EXPECT_NEAR(
      all.aae_deg,
      (45 + degrees(std::acos(1 / std::sqrt(26.0))) + degrees(std::acos(1 / std::sqrt(5.0)))) / 4,
      1e-6);
  EXPECT_DOUBLE_EQ(all.r1, 50.0);
  EXPECT_DOUBLE_EQ(all.r3, 25.0);
}

TEST(Metrics, NoCountedPixelGivesZeros) {
  const FlowErrors e = flow_errors(one_pixel(4, 4), one_pixel(kUnknown, kUnknown));
  EXPECT_EQ(e.pixels, 0);
  EXPECT_EQ(e.epe, 0.0);
  EXPECT_EQ(e.aae_deg, 0.0);
  EXPECT_EQ(e.r1, 0.0);
  EXPECT_EQ(e.r3, 0.0);
  EXPECT_EQ(e.fl, 0.0);
}

TEST(Metrics, MatchesAStraightforwardReferenceOnAView) {
  cv::Mat big_est(40, 50, CV_32FC2);
  cv::Mat big_gt(40, 50, CV_32FC2);
  cv::RNG rng(7);
  rng.fill(big_est, cv::RNG::UNIFORM, cv::Scalar::all(-6), cv::Scalar::all(6));
  rng.fill(big_gt, cv::RNG::UNIFORM, cv::Scalar::all(-6), cv::Scalar::all(6));
  for (int i = 0; i < 100; ++i) {
    big_gt.at<cv::Vec2f>(rng.uniform(0, 40), rng.uniform(0, 50)) = {kUnknown, 0};
  }
  const cv::Rect roi(3, 5, 41, 30);
  const cv::Mat est = big_est(roi);
  const cv::Mat gt = big_gt(roi);

  double angle = 0, epe = 0;
  int n = 0, over1 = 0, over3 = 0, outliers = 0;
  for (int y = 0; y < gt.rows; ++y) {
    for (int x = 0; x < gt.cols; ++x) {
      const cv::Vec2f g = gt.at<cv::Vec2f>(y, x);
      if (std::abs(g[0]) > 1e9f) continue;
      const cv::Vec2f f = est.at<cv::Vec2f>(y, x);
      const cv::Vec3d a(f[0], f[1], 1), b(g[0], g[1], 1);
      angle += std::acos(a.dot(b) / (cv::norm(a) * cv::norm(b)));
      const double d = cv::norm(cv::Vec2d(f) - cv::Vec2d(g));
      epe += d;
      over1 += d > 1;
      over3 += d > 3;
      outliers += d > 3 && d > 0.05 * cv::norm(cv::Vec2d(g));
      ++n;
    }
  }
  const FlowErrors e = flow_errors(est, gt);
  ASSERT_EQ(e.pixels, n);
  EXPECT_NEAR(e.aae_deg, degrees(angle / n), 1e-9);
  EXPECT_NEAR(e.epe, epe / n, 1e-9);
  EXPECT_DOUBLE_EQ(e.r1, 100.0 * over1 / n);
  EXPECT_DOUBLE_EQ(e.r3, 100.0 * over3 / n);
  EXPECT_DOUBLE_EQ(e.fl, 100.0 * outliers / n);
}

// KITTI's outlier: EPE > 3 px AND EPE > 5 % of the true magnitude; both bounds strict.
TEST(Metrics, FlNeedsBothThreePixelsAndFivePercent) {
  struct Case {
    cv::Vec2f estimate, truth;
    bool outlier;
  };
  const Case cases[] = {
      {{104, 0}, {100, 0}, false},  // EPE 4 > 3 but only 4 % of 100
      {{106, 0}, {100, 0}, true},   // EPE 6 > 3 and 6 %
      {{105, 0}, {100, 0}, false},  // exactly 5 %: not over it
      {{3, 0}, {0, 0}, false},      // EPE exactly 3
      {{3.5f, 0}, {0, 0}, true},    // zero motion: any EPE over 3 is over 5 %
      {{13.5f, 0}, {10, 0}, true},  // 3.5 > 3 and > 0.5
      {{0, 0}, {80, 60}, true},     // EPE 100 against |100|: 100 %
      {{84, 63}, {80, 60}, false},  // EPE 5 = exactly 5 % of 100
  };
  cv::Mat estimate(1, std::size(cases), CV_32FC2);
  cv::Mat truth(1, std::size(cases), CV_32FC2);
  int outliers = 0;
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    estimate.at<cv::Vec2f>(0, static_cast<int>(i)) = cases[i].estimate;
    truth.at<cv::Vec2f>(0, static_cast<int>(i)) = cases[i].truth;
    const FlowErrors single = flow_errors(one_pixel(cases[i].estimate[0], cases[i].estimate[1]),
                                          one_pixel(cases[i].truth[0], cases[i].truth[1]));
    EXPECT_EQ(single.fl, cases[i].outlier ? 100.0 : 0.0) << "case " << i;
    outliers += cases[i].outlier;
  }
  EXPECT_DOUBLE_EQ(flow_errors(estimate, truth).fl, 100.0 * outliers / std::size(cases));

  // Excluded and unknown pixels are not in the denominator either.
  cv::Mat exclude(1, std::size(cases), CV_8UC1, cv::Scalar(0));
  exclude.at<uchar>(0, 0) = 1;                // a non-outlier
  truth.at<cv::Vec2f>(0, 1) = {kUnknown, 0};  // an outlier
  EXPECT_DOUBLE_EQ(flow_errors(estimate, truth, exclude).fl,
                   100.0 * (outliers - 1) / (std::size(cases) - 2));
}

TEST(Metrics, NonFiniteEstimateAtACountedPixelThrows) {
  Mixed m;
  m.estimate.at<cv::Vec2f>(1, 2) = {kNaN, 0};
  try {
    flow_errors(m.estimate, m.ground_truth);
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("at (2,1)"), std::string::npos) << e.what();
  }
  m.estimate.at<cv::Vec2f>(1, 2) = {1, 1};
  m.estimate.at<cv::Vec2f>(1, 1) = {0, kInf};
  EXPECT_THROW(flow_errors(m.estimate, m.ground_truth), Error);
  EXPECT_THROW(endpoint_error_image(m.estimate, m.ground_truth), Error);
  EXPECT_NO_THROW(flow_errors(m.estimate, m.ground_truth, m.exclude));  // (1,1) is excluded
}

TEST(Metrics, MismatchesThrowNamingBothSizes) {
  const cv::Mat a(3, 4, CV_32FC2, cv::Scalar(0, 0));
  const cv::Mat b(3, 5, CV_32FC2, cv::Scalar(0, 0));
  try {
    flow_errors(a, b);
    FAIL() << "no throw";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("4x3"), std::string::npos) << what;
    EXPECT_NE(what.find("5x3"), std::string::npos) << what;
  }
  EXPECT_THROW(flow_errors(cv::Mat(3, 4, CV_32FC1, cv::Scalar(0)), a), Error);
  EXPECT_THROW(flow_errors(a, cv::Mat(3, 4, CV_64FC2, cv::Scalar(0))), Error);
  EXPECT_THROW(flow_errors(a, a, cv::Mat(3, 4, CV_32FC1, cv::Scalar(0))), Error);
  EXPECT_THROW(flow_errors(a, a, cv::Mat(4, 3, CV_8UC1, cv::Scalar(0))), Error);
  EXPECT_THROW(endpoint_error_image(a, b), Error);
}

TEST(Metrics, EndpointErrorImage) {
  const Mixed m;
  const cv::Mat epe = endpoint_error_image(m.estimate, m.ground_truth);
  ASSERT_EQ(epe.type(), CV_32FC1);
  ASSERT_EQ(epe.size(), m.estimate.size());
  EXPECT_EQ(epe.at<float>(0, 0), 1.f);
  EXPECT_EQ(epe.at<float>(0, 1), 0.f);  // unknown
  EXPECT_EQ(epe.at<float>(0, 2), 0.f);  // unknown
  EXPECT_EQ(epe.at<float>(1, 0), 5.f);
  EXPECT_EQ(epe.at<float>(1, 1), 2.f);
  EXPECT_EQ(epe.at<float>(1, 2), 0.f);
}

}  // namespace
}  // namespace roiflow::flow
