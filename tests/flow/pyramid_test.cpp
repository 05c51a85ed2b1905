#include "flow/pyramid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/lk_kernels.hpp"
#include "test_util.hpp"

namespace roiflow::flow {
namespace {

using test::error_message;

// A smooth random texture and the same texture moved by a sub-pixel translation.
struct Pair {
  cv::Mat frame0, frame1;
};

Pair moving_pair(cv::Size size, std::uint64_t seed) {
  cv::Mat noise(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  Pair pair;
  cv::GaussianBlur(noise, pair.frame0, cv::Size(), 1.5);
  const cv::Matx23d shift(1, 0, 1.3, 0, 1, -0.7);
  cv::warpAffine(pair.frame0, pair.frame1, shift, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return pair;
}

cv::Mat random_image(cv::Size size, int type, std::uint64_t seed) {
  cv::Mat m(size, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, type == CV_16UC1 ? 65536 : 256);
  return m;
}

TEST(PyramidTest, EffectiveLevelsStopAtTheMinimumSide) {
  EXPECT_EQ(effective_levels({320, 240}, 3), 3);
  EXPECT_EQ(effective_levels({320, 240}, 1), 1);
  // 480 -> 240 -> 120 -> 60 -> 30 -> 15: all six levels keep >= 12 px.
  EXPECT_EQ(effective_levels({640, 480}, 6), 6);
  // 20 -> 10 < 12: only level 0.
  EXPECT_EQ(effective_levels({20, 20}, 6), 1);
  // 24 -> 12 (allowed) -> 6 (not).
  EXPECT_EQ(effective_levels({24, 24}, 6), 2);
  // 23 -> 12 -> 6: odd sides round up, like cv::pyrDown.
  EXPECT_EQ(effective_levels({23, 23}, 6), 2);
  // The short side decides.
  EXPECT_EQ(effective_levels({1000, 22}, 6), 1);
  EXPECT_EQ(effective_levels({22, 1000}, 6), 1);
  EXPECT_EQ(effective_levels({1, 1}, 6), 1);
  EXPECT_EQ(effective_levels({1, 50}, 3), 1);
}

TEST(PyramidTest, EffectiveLevelsRejectOutOfRangeRequests) {
  for (const int bad : {0, -1, kMaxLevels + 1, 100}) {
    const std::string msg = error_message([&] { effective_levels({320, 240}, bad); });
    EXPECT_NE(msg.find("got " + std::to_string(bad)), std::string::npos) << msg;
    EXPECT_THROW(build_pyramid(cv::Mat(32, 32, CV_8UC1, cv::Scalar(1)), bad, 0.0), Error);
  }
}

TEST(PyramidTest, LevelsHaveHalvedRoundedUpSizesAndRespectTheMinimumSide) {
  for (const cv::Size size :
       {cv::Size(321, 241), cv::Size(320, 240), cv::Size(20, 20), cv::Size(23, 23),
        cv::Size(97, 13), cv::Size(13, 200), cv::Size(1, 1), cv::Size(7, 5)}) {
    const cv::Mat image = random_image(size, CV_8UC1, 1);
    for (int requested = 1; requested <= kMaxLevels; ++requested) {
      const Pyramid pyr = build_pyramid(image, requested, 1.0);
      ASSERT_EQ(pyr.num_levels(), effective_levels(size, requested)) << size;
      ASSERT_LE(pyr.num_levels(), requested);
      EXPECT_EQ(pyr.size(), size);
      for (int l = 0; l < pyr.num_levels(); ++l) {
        const cv::Mat& level = pyr.levels[l];
        EXPECT_EQ(level.type(), CV_32FC1);
        EXPECT_EQ(level.size(), level_size(size, l)) << size << " level " << l;
        if (l > 0) {
          const cv::Size prev = pyr.levels[l - 1].size();
          EXPECT_EQ(level.size(), cv::Size((prev.width + 1) / 2, (prev.height + 1) / 2))
              << size << " level " << l;
          EXPECT_GE(std::min(level.cols, level.rows), kMinLevelSide) << size << " level " << l;
        }
      }
      // Stopped early only because one more level would be too small.
      if (pyr.num_levels() < requested) {
        const cv::Size last = pyr.levels.back().size();
        EXPECT_LT(std::min((last.width + 1) / 2, (last.height + 1) / 2), kMinLevelSide) << size;
      }
    }
  }
  const Pyramid odd = build_pyramid(random_image({321, 241}, CV_8UC1, 2), 3, 0.5);
  EXPECT_EQ(odd.levels[1].size(), cv::Size(161, 121));
  EXPECT_EQ(odd.levels[2].size(), cv::Size(81, 61));
}

TEST(PyramidTest, AcceptedTypesAreScaledToUnitRange) {
  const cv::Size size(40, 30);
  struct Case {
    cv::Mat image;
    float expected;
  };
  const Case cases[] = {
      {cv::Mat(size, CV_8UC1, cv::Scalar(255)), 1.f},
      {cv::Mat(size, CV_8UC1, cv::Scalar(51)), 0.2f},
      {cv::Mat(size, CV_8UC3, cv::Scalar(255, 255, 255)), 1.f},
      {cv::Mat(size, CV_8UC3, cv::Scalar(102, 102, 102)), 0.4f},
      {cv::Mat(size, CV_16UC1, cv::Scalar(65535)), 1.f},
      {cv::Mat(size, CV_16UC1, cv::Scalar(13107)), 0.2f},
      {cv::Mat(size, CV_32FC1, cv::Scalar(0.25)), 0.25f},
  };
  for (const Case& c : cases) {
    for (const double sigma : {0.0, 2.0}) {
      const Pyramid pyr = build_pyramid(c.image, 2, sigma);
      ASSERT_EQ(pyr.num_levels(), 2);
      for (const cv::Mat& level : pyr.levels) {
        ASSERT_EQ(level.type(), CV_32FC1);
        double lo = 0, hi = 0;
        cv::minMaxLoc(level, &lo, &hi);
        EXPECT_NEAR(lo, c.expected, 1e-6) << cv::typeToString(c.image.type());
        EXPECT_NEAR(hi, c.expected, 1e-6) << cv::typeToString(c.image.type());
      }
    }
  }
  // BGR is converted to luminance: pure blue, green and red differ.
  const Pyramid blue = build_pyramid(cv::Mat(size, CV_8UC3, cv::Scalar(255, 0, 0)), 1, 0.0);
  const Pyramid red = build_pyramid(cv::Mat(size, CV_8UC3, cv::Scalar(0, 0, 255)), 1, 0.0);
  EXPECT_NEAR(blue.levels[0].at<float>(0, 0), 0.114f, 0.005f);
  EXPECT_NEAR(red.levels[0].at<float>(0, 0), 0.299f, 0.005f);
}

// The pretreatment is computed by roiflow's own fused pass for small kernels; it must be what
// OpenCV's GaussianBlur (borders replicated) gives on the image in [0, 1], for every input
// type, for views into a larger image and for images smaller than the kernel.
TEST(PyramidTest, PretreatmentIsOpenCvsGaussianBlur) {
  const cv::Mat big = random_image({97, 61}, CV_8UC1, 11);
  cv::Mat big16, bigf;
  big.convertTo(big16, CV_16U, 257.0);
  big.convertTo(bigf, CV_32F, 1.0 / 255.0);
  struct Case {
    cv::Mat image;
    double scale;
  };
  const std::vector<Case> cases = {
      {big, 1.0 / 255.0},
      {big(cv::Rect(5, 7, 40, 30)), 1.0 / 255.0},
      {big(cv::Rect(0, 0, 3, 2)), 1.0 / 255.0},
      {big(cv::Rect(10, 10, 1, 1)), 1.0 / 255.0},
      {big16(cv::Rect(3, 4, 50, 33)), 1.0 / 65535.0},
      {bigf(cv::Rect(2, 1, 31, 45)), 1.0},
  };
  for (const Case& c : cases) {
    for (const double sigma : {0.2, 0.5, 0.8, 1.1, 1.6, 3.0}) {
      SCOPED_TRACE(cv::typeToString(c.image.type()) + " " + std::to_string(c.image.cols) + "x" +
                   std::to_string(c.image.rows) + " sigma " + std::to_string(sigma));
      cv::Mat unit, expected;
      c.image.convertTo(unit, CV_32F, c.scale);
      cv::GaussianBlur(unit, expected, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
      const Pyramid pyr = build_pyramid(c.image, 1, sigma);
      ASSERT_EQ(pyr.levels[0].size(), c.image.size());
      EXPECT_LT(cv::norm(pyr.levels[0], expected, cv::NORM_INF), 1e-6);
    }
  }
  // A part of a frame gets the frame's values wherever the kernel stays inside the part.
  const Pyramid whole = build_pyramid(big, 1, 0.5);
  const cv::Rect part(20, 12, 41, 33);
  const Pyramid piece = build_pyramid(big(part), 1, 0.5);
  const cv::Rect inner(2, 2, part.width - 4, part.height - 4);
  EXPECT_EQ(cv::norm(piece.levels[0](inner), whole.levels[0](inner + part.tl()), cv::NORM_INF),
            0.0);
}

TEST(PyramidTest, LevelZeroIsTheInputAndCoarserLevelsArePyrDown) {
  const cv::Mat image = random_image({64, 48}, CV_8UC1, 3);
  cv::Mat unit;
  image.convertTo(unit, CV_32F, 1.0 / 255.0);
  const Pyramid raw = build_pyramid(image, 3, 0.0);
  EXPECT_EQ(cv::norm(raw.levels[0], unit, cv::NORM_INF), 0.0);
  for (int l = 1; l < raw.num_levels(); ++l) {
    cv::Mat down;
    cv::pyrDown(raw.levels[l - 1], down);
    EXPECT_EQ(cv::norm(raw.levels[l], down, cv::NORM_INF), 0.0) << l;
  }
  // The pretreatment smooths: uniform noise loses variance, the mean stays.
  const Pyramid smooth = build_pyramid(image, 1, 1.5);
  cv::Scalar raw_mean, raw_std, smooth_mean, smooth_std;
  cv::meanStdDev(raw.levels[0], raw_mean, raw_std);
  cv::meanStdDev(smooth.levels[0], smooth_mean, smooth_std);
  EXPECT_LT(smooth_std[0], 0.5 * raw_std[0]);
  EXPECT_NEAR(smooth_mean[0], raw_mean[0], 0.01);
}

// Level 1 is made in the pass that makes level 0, and the coarser levels by the kernels' row
// steps: both must give cv::pyrDown's floats exactly, whatever the size (odd sides, rows that
// end inside a vector, frames narrower than two vectors), with every instruction set.
TEST(PyramidTest, FusedLevelsAreCvPyrDownBitForBit) {
  const cv::Size sizes[] = {{640, 480}, {584, 388}, {1242, 375}, {621, 188}, {83, 61},
                            {37, 29},   {13, 9},    {9, 7},      {8, 3},     {71, 33}};
  const detail::LkKernels* kinds[8];
  const int n = detail::available_lk_kernels(kinds, 8);
  for (int k = 0; k < n; ++k) {
    detail::set_lk_kernels_for_testing(kinds[k]);
    for (const cv::Size size : sizes) {
      const cv::Mat image = random_image(size, CV_8UC1, 11);
      for (const double sigma : {0.5, 0.0}) {
        const Pyramid pyr = build_pyramid(image, 4, sigma);
        for (int l = 1; l < pyr.num_levels(); ++l) {
          cv::Mat down;
          cv::pyrDown(pyr.levels[l - 1], down);
          ASSERT_EQ(pyr.levels[l].size(), down.size());
          EXPECT_EQ(cv::norm(pyr.levels[l], down, cv::NORM_INF), 0.0)
              << kinds[k]->name << " " << size << " sigma " << sigma << " level " << l;
        }
      }
    }
  }
  detail::set_lk_kernels_for_testing(nullptr);
}

TEST(PyramidTest, RejectsEmptyImagesAndOtherTypes) {
  EXPECT_THROW(build_pyramid(cv::Mat(), 3, 1.0), Error);
  for (const int type : {CV_64FC1, CV_8UC2, CV_8UC4, CV_16SC1, CV_32FC3, CV_32SC1}) {
    const cv::Mat image(16, 16, type, cv::Scalar::all(1));
    const std::string msg = error_message([&] { build_pyramid(image, 1, 1.0); });
    EXPECT_NE(msg.find(cv::typeToString(type)), std::string::npos) << msg;
  }
}

TEST(PyramidTest, SigmaOutOfRangeThrows) {
  const cv::Mat image(32, 32, CV_8UC1, cv::Scalar(5));
  EXPECT_NO_THROW(build_pyramid(image, 1, 0.0));
  EXPECT_NO_THROW(build_pyramid(image, 1, 20.0));
  for (const double bad : {-0.5, 20.5, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    const std::string msg = error_message([&] { build_pyramid(image, 1, bad); });
    EXPECT_NE(msg.find("sigma"), std::string::npos) << bad << ": " << msg;
  }
  EXPECT_NE(error_message([&] { build_pyramid(image, 1, -0.5); }).find("-0.5"), std::string::npos);
}

TEST(PyramidTest, LevelByLevelEqualsTheWholeBuildAndReusesBuffers) {
  const cv::Mat image = random_image({101, 77}, CV_8UC1, 4);
  const Pyramid whole = build_pyramid(image, 4, 0.8);
  Pyramid steps;
  for (int round = 0; round < 2; ++round) {
    std::vector<const uchar*> before;
    for (const cv::Mat& level : steps.levels)
      before.push_back(level.data);
    build_base_level(image, 4, 0.8, steps);
    ASSERT_EQ(steps.num_levels(), whole.num_levels());
    for (int l = 1; l < steps.num_levels(); ++l)
      build_level(steps, l);
    for (int l = 0; l < steps.num_levels(); ++l) {
      EXPECT_EQ(cv::norm(steps.levels[l], whole.levels[l], cv::NORM_INF), 0.0) << l;
      if (round == 1) {
        EXPECT_EQ(steps.levels[l].data, before[l]) << l;
      }
    }
  }
  EXPECT_THROW(build_level(steps, 0), Error);
  EXPECT_THROW(build_level(steps, steps.num_levels()), Error);
}

TEST(PyramidTest, APartOnTheCoarsestGridIsThePyramidOfThePart) {
  const cv::Mat image = random_image({120, 90}, CV_8UC1, 5);
  const Pyramid whole = build_pyramid(image, 3, 0.5);
  const cv::Rect rect(24, 8, 61, 50);  // origin on multiples of 4
  Pyramid part;
  build_pyramid_part(image, rect, 3, 0.5, part);
  const Pyramid expected = build_pyramid(image(rect), 3, 0.5);
  ASSERT_EQ(part.num_levels(), 3);
  for (int l = 0; l < 3; ++l) {
    EXPECT_EQ(cv::norm(part.levels[l], expected.levels[l], cv::NORM_INF), 0.0) << l;
    // Away from the part's edges it is the frame's own pyramid.
    const cv::Rect at = part_level_rect(rect, l);
    EXPECT_EQ(part.levels[l].size(), at.size()) << l;
    const cv::Rect inner(4, 4, at.width - 8, at.height - 8);
    EXPECT_LT(cv::norm(part.levels[l](inner), whole.levels[l](inner + at.tl()), cv::NORM_INF), 1e-6)
        << l;
  }
  for (const cv::Rect bad : {cv::Rect(2, 8, 40, 40), cv::Rect(24, 6, 40, 40),
                             cv::Rect(100, 8, 40, 40), cv::Rect(24, 8, 0, 40)}) {
    const std::string msg = error_message([&] { build_pyramid_part(image, bad, 3, 0.5, part); });
    EXPECT_NE(msg.find("multiple of 4"), std::string::npos) << msg;
  }
}

TEST(PyramidTest, IdenticalFramesGiveZeroFlow) {
  for (const cv::Size size : {cv::Size(160, 120), cv::Size(33, 17)}) {
    const Pair s = moving_pair(size, 5);
    for (const std::string& preset : LkParams::preset_names()) {
      const LkParams params = LkParams::preset(preset);
      const Pyramid pyr =
          build_pyramid(s.frame0, flow_pyramid_levels(size, params, {}), params.sigma);
      const FlowResult r = dense_flow(pyr, pyr, params);
      ASSERT_EQ(r.flow.size(), size);
      // Not bit-exact: see the measured value in DenseLkTest.TinyImages... (1 ulp of the
      // bilinear warp in the last row and column).
      EXPECT_LT(cv::norm(r.flow, cv::NORM_INF), 1e-6) << preset << " " << size;
    }
  }
}

TEST(PyramidTest, PyramidOverloadEqualsImageOverload) {
  const Pair s = moving_pair({160, 120}, 8);
  for (const std::string& preset : LkParams::preset_names()) {
    const LkParams params = LkParams::preset(preset);
    const FlowResult from_images = dense_flow(s.frame0, s.frame1, params);
    // A pyramid with more levels than needed is fine: the extra ones are ignored.
    const Pyramid p0 = build_pyramid(s.frame0, kMaxLevels, params.sigma);
    const Pyramid p1 = build_pyramid(s.frame1, kMaxLevels, params.sigma);
    const FlowResult from_pyramids = dense_flow(p0, p1, params);
    EXPECT_EQ(cv::norm(from_images.flow, from_pyramids.flow, cv::NORM_INF), 0.0) << preset;
  }
}

}  // namespace
}  // namespace roiflow::flow
