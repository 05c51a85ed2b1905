#include "eval/kitti_flow.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "core/atomic_write.hpp"
#include "flow/metrics.hpp"
#include "test_util.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;

using KittiFlowTest = test::TempDirTest;

cv::Vec3w bgr(int b, int g, int r) {
  return {static_cast<ushort>(b), static_cast<ushort>(g), static_cast<ushort>(r)};
}

TEST(KittiFlow, DecodesTheDevkitFormulaWithRedAsU) {
  // Written by hand: u = (R - 32768) / 64 in channel 2, v = (G - 32768) / 64 in channel 1.
  cv::Mat png(1, 4, CV_16UC3);
  png.at<cv::Vec3w>(0, 0) = bgr(1, 32768 + 64, 32768 - 128);  // (-2, 1)
  png.at<cv::Vec3w>(0, 1) = bgr(1, 0, 65535);                 // (511.984375, -512)
  png.at<cv::Vec3w>(0, 2) = bgr(0, 32768 + 64, 32768 + 64);   // invalid
  png.at<cv::Vec3w>(0, 3) = bgr(7, 32768 + 1, 32768);         // any B > 0 is valid: (0, 1/64)
  const cv::Mat flow = decode_kitti_flow(png);
  ASSERT_EQ(flow.type(), CV_32FC2);
  ASSERT_EQ(flow.size(), cv::Size(4, 1));
  EXPECT_EQ(flow.at<cv::Vec2f>(0, 0), cv::Vec2f(-2.f, 1.f));
  EXPECT_EQ(flow.at<cv::Vec2f>(0, 1), cv::Vec2f(511.984375f, -512.f));
  EXPECT_FALSE(flow::is_known_flow(flow.at<cv::Vec2f>(0, 2)[0], flow.at<cv::Vec2f>(0, 2)[1]));
  EXPECT_EQ(flow.at<cv::Vec2f>(0, 3), cv::Vec2f(0.f, 1.f / 64));
}

TEST(KittiFlow, EncodeRoundsToOneSixtyFourthAndMarksUnknownInvalid) {
  cv::Mat flow(2, 3, CV_32FC2);
  flow.at<cv::Vec2f>(0, 0) = {1.5f, -0.25f};
  flow.at<cv::Vec2f>(0, 1) = {0.01f, 0.02f};  // 0.64 and 1.28 sixty-fourths: round to 1 and 1
  flow.at<cv::Vec2f>(0, 2) = {1e10f, 0};
  flow.at<cv::Vec2f>(1, 0) = {std::numeric_limits<float>::quiet_NaN(), 0};
  flow.at<cv::Vec2f>(1, 1) = {-512.f, 511.984375f};
  flow.at<cv::Vec2f>(1, 2) = {0, 0};
  const cv::Mat png = encode_kitti_flow(flow);
  ASSERT_EQ(png.type(), CV_16UC3);
  EXPECT_EQ(png.at<cv::Vec3w>(0, 0), bgr(1, 32768 - 16, 32768 + 96));
  EXPECT_EQ(png.at<cv::Vec3w>(0, 1), bgr(1, 32768 + 1, 32768 + 1));
  EXPECT_EQ(png.at<cv::Vec3w>(0, 2), bgr(0, 0, 0));
  EXPECT_EQ(png.at<cv::Vec3w>(1, 0), bgr(0, 0, 0));
  EXPECT_EQ(png.at<cv::Vec3w>(1, 1), bgr(1, 65535, 0));
  EXPECT_EQ(png.at<cv::Vec3w>(1, 2), bgr(1, 32768, 32768));

  const cv::Mat back = decode_kitti_flow(png);
  EXPECT_EQ(back.at<cv::Vec2f>(0, 0), cv::Vec2f(1.5f, -0.25f));
  EXPECT_EQ(back.at<cv::Vec2f>(1, 1), cv::Vec2f(-512.f, 511.984375f));
  EXPECT_FALSE(flow::is_known_flow(back.at<cv::Vec2f>(1, 0)[0], back.at<cv::Vec2f>(1, 0)[1]));
}

TEST(KittiFlow, RandomFlowRoundTripsWithinHalfAStep) {
  cv::Mat flow(17, 23, CV_32FC2);
  cv::RNG rng(3);
  rng.fill(flow, cv::RNG::UNIFORM, -300, 300);
  const cv::Mat back = decode_kitti_flow(encode_kitti_flow(flow));
  EXPECT_LE(cv::norm(back, flow, cv::NORM_INF), 0.5 / 64 + 1e-6);
}

TEST(KittiFlow, OutOfRangeFlowThrowsInsteadOfClamping) {
  for (float u : {512.f, -512.01f, 1000.f}) {
    const cv::Mat flow(1, 2, CV_32FC2, cv::Scalar(0, u));
    const std::string message = test::error_message([&] { encode_kitti_flow(flow); });
    EXPECT_NE(message.find("outside the KITTI range"), std::string::npos) << u << ": " << message;
  }
  EXPECT_NE(
      test::error_message([&] { encode_kitti_flow(cv::Mat(2, 2, CV_32FC1)); }).find("CV_32FC2"),
      std::string::npos);
}

TEST(KittiFlow, OutOfRangeFlowCanBeWrittenInvalidInstead) {
  cv::Mat flow(1, 3, CV_32FC2, cv::Scalar(1.5, -2.25));
  flow.at<cv::Vec2f>(0, 1) = {600.f, 0.f};
  const cv::Mat png = encode_kitti_flow(flow, /*out_of_range_invalid=*/true);
  EXPECT_EQ(png.at<cv::Vec3w>(0, 1), cv::Vec3w(0, 0, 0));
  const cv::Mat back = decode_kitti_flow(png);
  EXPECT_FALSE(flow::is_known_flow(back.at<cv::Vec2f>(0, 1)[0], back.at<cv::Vec2f>(0, 1)[1]));
  EXPECT_EQ(back.at<cv::Vec2f>(0, 0), cv::Vec2f(1.5f, -2.25f));
  EXPECT_EQ(back.at<cv::Vec2f>(0, 2), cv::Vec2f(1.5f, -2.25f));
}

TEST(KittiFlow, DecodeRejectsWhatIsNotSixteenBitThreeChannel) {
  for (const cv::Mat& bad :
       {cv::Mat(), cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(1)),
        cv::Mat(2, 2, CV_16UC1, cv::Scalar(1)), cv::Mat(2, 2, CV_16UC4, cv::Scalar::all(1))}) {
    EXPECT_NE(test::error_message([&] { decode_kitti_flow(bad); }).find("16-bit 3-channel"),
              std::string::npos);
  }
}

TEST_F(KittiFlowTest, FileRoundTripAndErrorsNameTheFile) {
  cv::Mat flow(9, 11, CV_32FC2, cv::Scalar(2.25, -7.5));
  flow.at<cv::Vec2f>(4, 5) = {1e10f, 1e10f};
  write_kitti_flow(path("gt.png"), flow);
  EXPECT_FALSE(fs::exists(partial_path(path("gt.png"))));
  const cv::Mat png = cv::imread(path("gt.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC3);  // a real 16-bit file, as KITTI's devkit reads it
  const cv::Mat back = read_kitti_flow(path("gt.png"));
  EXPECT_EQ(back.at<cv::Vec2f>(0, 0), cv::Vec2f(2.25f, -7.5f));
  EXPECT_EQ(back.at<cv::Vec2f>(8, 10), cv::Vec2f(2.25f, -7.5f));
  EXPECT_FALSE(flow::is_known_flow(back.at<cv::Vec2f>(4, 5)[0], back.at<cv::Vec2f>(4, 5)[1]));

  const std::string missing = path("missing.png");
  EXPECT_NE(test::error_message([&] { read_kitti_flow(missing); }).find(missing),
            std::string::npos);
  std::ofstream(path("garbage.png")) << "not a png";
  EXPECT_NE(test::error_message([&] { read_kitti_flow(path("garbage.png")); }).find("garbage.png"),
            std::string::npos);
  ASSERT_TRUE(cv::imwrite(path("eight_bit.png"), cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(9))));
  const std::string message = test::error_message([&] { read_kitti_flow(path("eight_bit.png")); });
  EXPECT_NE(message.find("eight_bit.png"), std::string::npos) << message;
  EXPECT_NE(message.find("16-bit"), std::string::npos) << message;
}

}  // namespace
}  // namespace roiflow::eval
