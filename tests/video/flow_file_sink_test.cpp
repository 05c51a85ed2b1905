#include "video/flow_file_sink.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"
#include "flow/metrics.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
using video::FlowFileFormat;
using video::FlowFileSink;
namespace fs = std::filesystem;

cv::Mat random_flow(int seed, float range = 40.f) {
  cv::Mat flow(48, 64, CV_32FC2);
  cv::RNG rng(seed);
  rng.fill(flow, cv::RNG::UNIFORM, cv::Scalar::all(-range), cv::Scalar::all(range));
  return flow;
}

class FlowFileSinkTest : public test::TempDirTest {};

TEST_F(FlowFileSinkTest, FloFilesHoldTheFlowExactlyInOrder) {
  const std::string dir = path("flow/nested");
  FlowFileSink sink(dir, FlowFileFormat::Flo);
  const cv::Mat a = random_flow(1), b = random_flow(2);
  sink.write(a);
  sink.write_encoded(sink.encode(b));
  EXPECT_EQ(sink.files(), 2);
  const cv::Mat ra = eval::read_flo(dir + "/000001.flo"), rb = eval::read_flo(dir + "/000002.flo");
  EXPECT_EQ(cv::norm(ra, a, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(rb, b, cv::NORM_INF), 0.0);
  EXPECT_FALSE(fs::exists(dir + "/000003.flo"));
}

TEST_F(FlowFileSinkTest, KittiFilesRoundTripToOneSixtyFourthAndKeepUnknownUnknown) {
  const std::string dir = path("kitti");
  FlowFileSink sink(dir, FlowFileFormat::Kitti);
  cv::Mat flow = random_flow(3, 300.f);
  flow.at<cv::Vec2f>(5, 7) = {1e10f, 1e10f};  // unknown
  flow.at<cv::Vec2f>(6, 7) = {700.f, 0.f};    // outside the format's range: written invalid
  cv::Mat exact(48, 64, CV_32FC2);            // multiples of 1/64 come back bit for bit
  cv::RNG rng(4);
  for (int y = 0; y < exact.rows; ++y) {
    for (int x = 0; x < exact.cols; ++x) {
      exact.at<cv::Vec2f>(y, x) = {static_cast<float>(rng.uniform(-32768, 32767)) / 64.f,
                                   static_cast<float>(rng.uniform(-32768, 32767)) / 64.f};
    }
  }
  sink.write(flow);
  sink.write(exact);
  const cv::Mat back = eval::read_kitti_flow(dir + "/000001.png");
  ASSERT_EQ(back.size(), flow.size());
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f f = flow.at<cv::Vec2f>(y, x), g = back.at<cv::Vec2f>(y, x);
      if ((y == 5 || y == 6) && x == 7) {
        EXPECT_FALSE(flow::is_known_flow(g[0], g[1])) << y;
        continue;
      }
      ASSERT_LE(std::abs(f[0] - g[0]), 1.f / 128 + 1e-4f) << x << "," << y;
      ASSERT_LE(std::abs(f[1] - g[1]), 1.f / 128 + 1e-4f) << x << "," << y;
    }
  }
  const cv::Mat back_exact = eval::read_kitti_flow(dir + "/000002.png");
  EXPECT_EQ(cv::norm(back_exact, exact, cv::NORM_INF), 0.0);
  // A tenth of a .flo's size or so (64x48x8 bytes = 24 KiB as .flo).
  EXPECT_LT(fs::file_size(dir + "/000002.png"), 64u * 48u * 8u);
}

TEST_F(FlowFileSinkTest, EncodingOnOtherThreadsGivesTheSameFiles) {
  FlowFileSink serial(path("a"), FlowFileFormat::Kitti), parallel(path("b"), FlowFileFormat::Kitti);
  std::vector<cv::Mat> flows, encoded(6);
  for (int i = 0; i < 6; ++i)
    flows.push_back(random_flow(10 + i));
  std::vector<std::thread> threads;
  for (int i = 0; i < 6; ++i)
    threads.emplace_back([&, i] { encoded[i] = parallel.encode(flows[i]); });
  for (std::thread& t : threads)
    t.join();
  for (int i = 0; i < 6; ++i) {
    serial.write(flows[i]);
    parallel.write_encoded(encoded[i]);
  }
  for (int i = 1; i <= 6; ++i) {
    const std::string name = "/00000" + std::to_string(i) + ".png";
    EXPECT_EQ(test::read_text(path("a") + name), test::read_text(path("b") + name)) << name;
  }
}

TEST_F(FlowFileSinkTest, BadInputThrowsClearly) {
  EXPECT_EQ(video::flow_file_format_from_string("kitti"), FlowFileFormat::Kitti);
  EXPECT_NE(test::error_message([] { video::flow_file_format_from_string("png"); }).find("png"),
            std::string::npos);
  FlowFileSink sink(path("x"), FlowFileFormat::Flo);
  EXPECT_NE(test::error_message([&] { sink.write(cv::Mat(4, 4, CV_32FC1)); }).find("CV_32FC2"),
            std::string::npos);
  // A KITTI sink's bytes are not a .flo sink's flow.
  FlowFileSink kitti(path("y"), FlowFileFormat::Kitti);
  EXPECT_THROW(sink.write_encoded(kitti.encode(random_flow(1))), Error);
  EXPECT_EQ(sink.files(), 0);
  std::ofstream(path("file")) << "x";
  EXPECT_THROW(FlowFileSink(path("file"), FlowFileFormat::Flo), Error);
}

}  // namespace
