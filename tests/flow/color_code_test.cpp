#include "flow/color_code.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.hpp"

namespace roiflow::flow {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kUnknown = 1.6666668e9f;

cv::Vec3b color(float u, float v, float max_magnitude) {
  return flow_to_color(cv::Mat(1, 1, CV_32FC2, cv::Scalar(u, v)), max_magnitude).at<cv::Vec3b>(0);
}

void expect_near(cv::Vec3b got, cv::Vec3b want, int tolerance = 0) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got[c], want[c], tolerance)
        << "channel " << c << ": got " << got << ", want " << want;
  }
}

// An independent reading of the Middlebury wheel (flowToColor.m): colours as RGB in [0,1]
// along the hue axis, built segment by segment with floor(), then interpolated in double.
cv::Vec3b reference_bgr(double u, double v) {
  const int segments[6] = {15, 6, 4, 11, 13, 6};
  // Each segment moves one channel from 0 to 255 or back; {channel, rising}.
  const int channel[6] = {1, 0, 2, 1, 0, 2};
  const bool rising[6] = {true, false, true, false, true, false};
  std::vector<cv::Vec3d> wheel;
  cv::Vec3d rgb(255, 0, 0);
  for (int s = 0; s < 6; ++s) {
    for (int i = 0; i < segments[s]; ++i) {
      const double ramp = std::floor(255.0 * i / segments[s]);
      rgb[channel[s]] = rising[s] ? ramp : 255 - ramp;
      wheel.push_back(rgb / 255.0);
    }
    rgb[channel[s]] = rising[s] ? 255 : 0;
  }
  const double n = static_cast<double>(wheel.size());
  const double rad = std::hypot(u, v);
  const double fk = (std::atan2(-v, -u) / std::numbers::pi + 1) / 2 * (n - 1);
  const int k0 = static_cast<int>(std::floor(fk));
  const int k1 = (k0 + 1) % static_cast<int>(n);
  const double f = fk - k0;
  cv::Vec3b bgr;
  for (int c = 0; c < 3; ++c) {
    double col = (1 - f) * wheel[k0][c] + f * wheel[k1][c];
    col = rad <= 1 ? 1 - rad * (1 - col) : col * 0.75;
    bgr[2 - c] = static_cast<uchar>(std::floor(255 * col));
  }
  return bgr;
}

TEST(ColorCode, CardinalDirectionsAreTheWheelAnchors) {
  // Right: fk = 0, wheel[0] = red.  Left: fk = 27, wheel[27] = CB step 2 = RGB (0, 209, 255).
  expect_near(color(1, 0, 1), {0, 0, 255});
  expect_near(color(-1, 0, 1), {255, 209, 0});
  // Down: fk = 13.5, halfway between RY 13 and 14 = RGB (255, 229.5, 0).
  expect_near(color(0, 1, 1), {0, 229, 255}, 1);
  // Up: fk = 40.5, halfway between BM 4 and 5 = RGB (88, 0, 255).
  expect_near(color(0, -1, 1), {255, 0, 88}, 1);
}

TEST(ColorCode, MagnitudeSetsSaturation) {
  expect_near(color(0.5f, 0, 1), {127, 127, 255});
  expect_near(color(2, 0, 1), {0, 0, 191});  // beyond the normalising magnitude: darkened
  expect_near(color(1, 0, 4), {191, 191, 255});
}

TEST(ColorCode, MatchesTheReferenceEverywhere) {
  cv::Mat flow(64, 64, CV_32FC2);
  cv::RNG rng(3);
  rng.fill(flow, cv::RNG::UNIFORM, cv::Scalar::all(-3), cv::Scalar::all(3));
  const float max_magnitude = 2.5f;  // some pixels exceed it
  const cv::Mat bgr = flow_to_color(flow, max_magnitude);
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
      SCOPED_TRACE(::testing::Message() << "flow " << f);
      expect_near(bgr.at<cv::Vec3b>(y, x),
                  reference_bgr(f[0] / max_magnitude, f[1] / max_magnitude), 1);
    }
  }
}

TEST(ColorCode, ZeroIsWhiteUnknownIsBlack) {
  cv::Mat flow(2, 3, CV_32FC2, cv::Scalar(0, 0));
  expect_near(flow_to_color(flow).at<cv::Vec3b>(1, 2), {255, 255, 255});  // no 0/0
  flow.at<cv::Vec2f>(0, 0) = {kUnknown, 0};
  flow.at<cv::Vec2f>(0, 1) = {kNaN, 1};
  flow.at<cv::Vec2f>(0, 2) = {0, -std::numeric_limits<float>::infinity()};
  flow.at<cv::Vec2f>(1, 0) = {2, 0};
  flow.at<cv::Vec2f>(1, 1) = {1, 0};
  const cv::Mat bgr = flow_to_color(flow);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.size(), flow.size());
  for (int x = 0; x < 3; ++x)
    expect_near(bgr.at<cv::Vec3b>(0, x), {0, 0, 0});
  // The unknown pixels must not count towards the automatic maximum (2 here).
  expect_near(bgr.at<cv::Vec3b>(1, 0), {0, 0, 255});
  expect_near(bgr.at<cv::Vec3b>(1, 1), {127, 127, 255});
  expect_near(bgr.at<cv::Vec3b>(1, 2), {255, 255, 255});
}

TEST(ColorCode, RejectsBadInput) {
  EXPECT_THROW(flow_to_color(cv::Mat()), Error);
  EXPECT_THROW(flow_to_color(cv::Mat(2, 2, CV_32FC1, cv::Scalar(0))), Error);
  EXPECT_THROW(flow_to_color(cv::Mat(2, 2, CV_32FC2, cv::Scalar(0, 0)),
                             std::numeric_limits<float>::infinity()),
               Error);
}

TEST(ColorCode, RobustMaximumIsANearestRankPercentile) {
  // Magnitudes 1..100 (3-4-5 triangles), one unknown pixel that must not count.
  cv::Mat flow(1, 101, CV_32FC2);
  for (int i = 0; i < 100; ++i)
    flow.at<cv::Vec2f>(0, i) = {0.6f * static_cast<float>(i + 1),
                                -0.8f * static_cast<float>(i + 1)};
  flow.at<cv::Vec2f>(0, 100) = {kUnknown, 0};
  EXPECT_NEAR(robust_max_magnitude(flow, 99.0), 99.f, 1e-4f);
  EXPECT_NEAR(robust_max_magnitude(flow, 50.0), 50.f, 1e-4f);
  EXPECT_NEAR(robust_max_magnitude(flow, 0.5), 1.f, 1e-4f);
  EXPECT_NEAR(max_magnitude(flow), 100.f, 1e-4f);
  EXPECT_EQ(robust_max_magnitude(cv::Mat(2, 2, CV_32FC2, cv::Scalar(kNaN, 0))), 0.f);
  EXPECT_THROW(robust_max_magnitude(flow, 0.0), Error);
  EXPECT_THROW(robust_max_magnitude(flow, 100.5), Error);
  EXPECT_THROW(robust_max_magnitude(cv::Mat(2, 2, CV_32FC1, cv::Scalar(0))), Error);
}

TEST(ColorCode, AFewOutliersDoNotWashThePictureOut) {
  // A smooth field up to 2 px and 0.2 % of its pixels at 50 px (border outliers of an
  // estimate): the automatic scale stays near 2, so a 1 px vector is still half saturated.
  cv::Mat flow(64, 64, CV_32FC2);
  cv::RNG rng(5);
  rng.fill(flow, cv::RNG::UNIFORM, cv::Scalar::all(-1.41), cv::Scalar::all(1.41));
  flow.at<cv::Vec2f>(10, 10) = {1, 0};
  for (int i = 0; i < 8; ++i)
    flow.at<cv::Vec2f>(0, 3 * i) = {50, 0};
  const float scale = robust_max_magnitude(flow);
  EXPECT_LT(scale, 2.f);
  EXPECT_GT(scale, 1.7f);
  const cv::Mat bgr = flow_to_color(flow);
  expect_near(bgr.at<cv::Vec3b>(10, 10), color(1, 0, scale), 0);
  // With the plain maximum the same vector would be nearly white: that is what must not happen.
  const cv::Vec3b washed = color(1, 0, max_magnitude(flow));
  EXPECT_GT(washed[0], 240);
  EXPECT_LT(bgr.at<cv::Vec3b>(10, 10)[0], 160);
  // The outliers themselves keep their hue (darkened red, not black).
  expect_near(bgr.at<cv::Vec3b>(0, 0), {0, 0, 191});
}

TEST(ColorCode, LegendAnchorsAndBackground) {
  const int size = 151;
  const int c = size / 2;
  const cv::Mat legend = color_wheel_legend(size);
  ASSERT_EQ(legend.type(), CV_8UC3);
  ASSERT_EQ(legend.size(), cv::Size(size, size));
  expect_near(legend.at<cv::Vec3b>(c, c), {255, 255, 255});
  expect_near(legend.at<cv::Vec3b>(c, size - 1), {0, 0, 255});       // right rim, full magnitude
  expect_near(legend.at<cv::Vec3b>(c, 0), {255, 209, 0});            // left rim
  expect_near(legend.at<cv::Vec3b>(size - 1, c), {0, 229, 255}, 1);  // bottom rim (down)
  expect_near(legend.at<cv::Vec3b>(0, 0), {255, 255, 255});          // outside the circle
  expect_near(legend.at<cv::Vec3b>(size - 1, size - 1), {255, 255, 255});
}

TEST(ColorCode, LegendIsSymmetricInMagnitude) {
  // Every wheel colour has a 255 and a 0 channel, so inside the circle the largest channel is
  // 255 and the smallest, 255 (1 - r), encodes the magnitude alone.
  for (const int size : {151, 40}) {
    const cv::Mat legend = color_wheel_legend(size);
    const double centre = (size - 1) / 2.0;
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const cv::Vec3b p = legend.at<cv::Vec3b>(y, x);
        const cv::Vec3b mirror = legend.at<cv::Vec3b>(size - 1 - y, size - 1 - x);
        const cv::Vec3b transposed = legend.at<cv::Vec3b>(x, y);
        const uchar lo = std::min({p[0], p[1], p[2]});
        EXPECT_EQ(lo, std::min({mirror[0], mirror[1], mirror[2]})) << x << "," << y;
        EXPECT_NEAR(lo, std::min({transposed[0], transposed[1], transposed[2]}), 1)
            << x << "," << y;
        if (std::hypot(x - centre, y - centre) < centre - 0.5) {
          EXPECT_EQ(std::max({p[0], p[1], p[2]}), 255) << x << "," << y;
        }
      }
    }
    // Saturation grows from the centre to the rim.
    const int row = size / 2;
    for (int x = size / 2 + 1; std::hypot(x - centre, row - centre) <= centre; ++x) {
      const cv::Vec3b a = legend.at<cv::Vec3b>(row, x - 1);
      const cv::Vec3b b = legend.at<cv::Vec3b>(row, x);
      EXPECT_LE(std::min({b[0], b[1], b[2]}), std::min({a[0], a[1], a[2]})) << x;
    }
  }
}

TEST(ColorCode, LegendRejectsTinySizes) {
  EXPECT_THROW(color_wheel_legend(2), Error);
  EXPECT_THROW(color_wheel_legend(0), Error);
  EXPECT_THROW(color_wheel_legend(-5), Error);
  EXPECT_NO_THROW(color_wheel_legend(3));
}

TEST(ColorCode, DrawsArrowsOnlyWhereFlowIsKnown) {
  const cv::Mat gray(48, 64, CV_8UC1, cv::Scalar(90));
  cv::Mat flow(48, 64, CV_32FC2, cv::Scalar(kUnknown, 0));
  cv::Mat expected_plain;
  cv::cvtColor(gray, expected_plain, cv::COLOR_GRAY2BGR);

  const cv::Mat none = draw_flow_vectors(gray, flow, 16);
  ASSERT_EQ(none.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(none, expected_plain, cv::NORM_INF), 0.0);

  flow.at<cv::Vec2f>(24, 24) = {6, 0};  // a sample point (step 16 starts at 8)
  flow.at<cv::Vec2f>(30, 30) = {6, 0};  // not a sample point
  const cv::Mat one = draw_flow_vectors(gray, flow, 16, 2.f);
  cv::Mat changed;
  cv::compare(one, expected_plain, changed, cv::CMP_NE);
  cv::Mat changed_any;
  cv::reduce(changed.reshape(1, static_cast<int>(changed.total())), changed_any, 1, cv::REDUCE_MAX);
  const cv::Rect box = cv::boundingRect(changed_any.reshape(1, changed.rows));
  EXPECT_EQ(box.x, 24);
  EXPECT_GE(box.x + box.width - 1, 24 + 11);  // arrow of length 6 * 2
  EXPECT_LE(box.x + box.width - 1, 24 + 13);
  EXPECT_GE(box.y, 24 - 4);
  EXPECT_LE(box.y + box.height - 1, 24 + 4);
  EXPECT_EQ(cv::countNonZero(gray != 90), 0);  // input untouched

  const cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(1, 2, 3));
  EXPECT_EQ(draw_flow_vectors(bgr, flow, 1).size(), bgr.size());
}

TEST(ColorCode, DrawRejectsBadInput) {
  const cv::Mat gray(8, 8, CV_8UC1, cv::Scalar(0));
  const cv::Mat flow(8, 8, CV_32FC2, cv::Scalar(1, 1));
  EXPECT_THROW(draw_flow_vectors(gray, cv::Mat(8, 9, CV_32FC2, cv::Scalar(0, 0))), Error);
  EXPECT_THROW(draw_flow_vectors(gray, cv::Mat(8, 8, CV_32FC1, cv::Scalar(0))), Error);
  EXPECT_THROW(draw_flow_vectors(gray, flow, 0), Error);
  EXPECT_THROW(draw_flow_vectors(cv::Mat(8, 8, CV_32FC1, cv::Scalar(0)), flow), Error);
  EXPECT_THROW(draw_flow_vectors(cv::Mat(), cv::Mat()), Error);
  EXPECT_THROW(draw_flow_vectors(gray, flow, 4, kNaN), Error);
}

}  // namespace
}  // namespace roiflow::flow
