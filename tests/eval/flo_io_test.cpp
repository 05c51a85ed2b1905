#include "eval/flo_io.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;

class FloIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::temp_directory_path() /
           ("roiflow_flo_io_" + name + "_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // A hand-made file, so the reader is tested against the format rather than against write_flo.
  std::string write_raw(const std::string& name, float magic, std::int32_t width,
                        std::int32_t height, const std::vector<float>& values,
                        const std::string& trailing = "") const {
    const std::string p = path(name);
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(&magic), sizeof magic);
    out.write(reinterpret_cast<const char*>(&width), sizeof width);
    out.write(reinterpret_cast<const char*>(&height), sizeof height);
    out.write(reinterpret_cast<const char*>(values.data()),
              static_cast<std::streamsize>(values.size() * sizeof(float)));
    out << trailing;
    return p;
  }

  fs::path dir_;
};

std::vector<float> ramp(std::size_t n) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = 0.25f * static_cast<float>(i) - 3.f;
  return v;
}

// The call must throw roiflow::Error whose message contains `needle` (the file, the value).
void expect_error(const std::function<void()>& call, const std::string& needle) {
  try {
    call();
    ADD_FAILURE() << "no roiflow::Error thrown, expected one mentioning '" << needle << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "message '" << e.what() << "' lacks '" << needle << "'";
  }
}

TEST_F(FloIoTest, RoundTripIsBitExactIncludingUnknownAndSpecialValues) {
  cv::Mat flow(7, 5, CV_32FC2);
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> dist(-50.f, 50.f);
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x)
      flow.at<cv::Vec2f>(y, x) = {dist(rng), dist(rng)};
  }
  flow.at<cv::Vec2f>(0, 0) = {1.6666668e9f, 1.6666668e9f};  // Middlebury's "unknown"
  flow.at<cv::Vec2f>(1, 2) = {-0.f, std::numeric_limits<float>::denorm_min()};
  flow.at<cv::Vec2f>(6, 4) = {std::numeric_limits<float>::infinity(), 1e-30f};

  const std::string p = path("round.flo");
  write_flo(p, flow);
  const cv::Mat back = read_flo(p);
  ASSERT_EQ(back.type(), CV_32FC2);
  ASSERT_EQ(back.size(), flow.size());
  ASSERT_TRUE(back.isContinuous());
  EXPECT_EQ(std::memcmp(back.data, flow.data, flow.total() * flow.elemSize()), 0);
  EXPECT_EQ(back.at<cv::Vec2f>(0, 0)[0], 1666666752.0f);
  EXPECT_FALSE(fs::exists(p + ".tmp"));
}

TEST_F(FloIoTest, WritesTheMiddleburyLayout) {
  cv::Mat flow(1, 2, CV_32FC2);
  flow.at<cv::Vec2f>(0, 0) = {1.5f, -2.f};
  flow.at<cv::Vec2f>(0, 1) = {3.f, 4.25f};
  const std::string p = path("layout.flo");
  write_flo(p, flow);

  std::ifstream in(p, std::ios::binary);
  float magic = 0;
  std::int32_t width = 0;
  std::int32_t height = 0;
  float values[5] = {};
  in.read(reinterpret_cast<char*>(&magic), 4);
  in.read(reinterpret_cast<char*>(&width), 4);
  in.read(reinterpret_cast<char*>(&height), 4);
  in.read(reinterpret_cast<char*>(values), sizeof values);
  EXPECT_EQ(in.gcount(), 16);  // exactly 4 floats after the header
  EXPECT_EQ(magic, 202021.25f);
  EXPECT_EQ(width, 2);
  EXPECT_EQ(height, 1);
  EXPECT_EQ(values[0], 1.5f);
  EXPECT_EQ(values[1], -2.f);
  EXPECT_EQ(values[2], 3.f);
  EXPECT_EQ(values[3], 4.25f);
}

TEST_F(FloIoTest, ReadsRowsTopToBottomWidthFirst) {
  const std::string p = write_raw("wide.flo", kFloMagic, 3, 2, ramp(3 * 2 * 2));
  const cv::Mat flow = read_flo(p);
  ASSERT_EQ(flow.cols, 3);
  ASSERT_EQ(flow.rows, 2);
  // Pixel (x=2, y=1) is the 6th pair: values 10 and 11 of the ramp.
  EXPECT_EQ(flow.at<cv::Vec2f>(1, 2)[0], 0.25f * 10 - 3.f);
  EXPECT_EQ(flow.at<cv::Vec2f>(1, 2)[1], 0.25f * 11 - 3.f);
}

TEST_F(FloIoTest, WritesANonContinuousView) {
  cv::Mat big(6, 8, CV_32FC2);
  cv::randu(big, cv::Scalar::all(-10), cv::Scalar::all(10));
  const cv::Mat view = big(cv::Rect(1, 2, 5, 3));
  ASSERT_FALSE(view.isContinuous());
  const std::string p = path("view.flo");
  write_flo(p, view);
  const cv::Mat back = read_flo(p);
  ASSERT_EQ(back.size(), view.size());
  EXPECT_EQ(cv::norm(back, view, cv::NORM_INF), 0.0);
}

TEST_F(FloIoTest, OverwritesAnExistingFile) {
  const std::string p = path("again.flo");
  write_flo(p, cv::Mat(4, 4, CV_32FC2, cv::Scalar(1, 2)));
  write_flo(p, cv::Mat(2, 3, CV_32FC2, cv::Scalar(5, 6)));
  const cv::Mat back = read_flo(p);
  EXPECT_EQ(back.size(), cv::Size(3, 2));
  EXPECT_EQ(back.at<cv::Vec2f>(1, 2), cv::Vec2f(5, 6));
}

TEST_F(FloIoTest, RejectsBadMagic) {
  const std::string p = write_raw("magic.flo", 202021.5f, 2, 2, ramp(8));
  expect_error([&] { read_flo(p); }, "magic");
  expect_error([&] { read_flo(p); }, p);
}

TEST_F(FloIoTest, RejectsNonPositiveDimensions) {
  const std::string negative = write_raw("neg.flo", kFloMagic, -2, 2, ramp(8));
  expect_error([&] { read_flo(negative); }, "-2x2");
  const std::string zero = write_raw("zero.flo", kFloMagic, 4, 0, {});
  expect_error([&] { read_flo(zero); }, "4x0");
}

TEST_F(FloIoTest, RejectsHugeDimensionsBeforeAllocating) {
  // Either header would ask for tens of gigabytes (or overflow); the tiny file must be refused
  // from its size alone, at once.
  const std::string absurd =
      write_raw("absurd.flo", kFloMagic, std::numeric_limits<std::int32_t>::max(), 3, ramp(2));
  const std::string big = write_raw("big.flo", kFloMagic, 60000, 60000, ramp(2));
  const auto start = std::chrono::steady_clock::now();
  expect_error([&] { read_flo(absurd); }, "2147483647x3");
  expect_error([&] { read_flo(big); }, "60000x60000");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
}

TEST_F(FloIoTest, RejectsTruncatedFile) {
  std::vector<float> values = ramp(4 * 3 * 2);
  values.pop_back();
  const std::string p = write_raw("short.flo", kFloMagic, 4, 3, values);
  expect_error([&] { read_flo(p); }, "truncated");
}

TEST_F(FloIoTest, RejectsTrailingBytes) {
  const std::string p = write_raw("long.flo", kFloMagic, 4, 3, ramp(4 * 3 * 2), "x");
  expect_error([&] { read_flo(p); }, "trailing");
}

TEST_F(FloIoTest, RejectsNaNAndSaysWhere) {
  std::vector<float> values = ramp(4 * 3 * 2);
  values[2 * (4 * 2 + 1) + 1] = std::numeric_limits<float>::quiet_NaN();  // v at (1, 2)
  const std::string p = write_raw("nan.flo", kFloMagic, 4, 3, values);
  expect_error([&] { read_flo(p); }, "NaN at (1,2)");
}

TEST_F(FloIoTest, RejectsEmptyShortMissingAndDirectory) {
  const std::string empty = path("empty.flo");
  std::ofstream(empty).close();
  expect_error([&] { read_flo(empty); }, empty);
  const std::string header_only = path("eight.flo");
  std::ofstream(header_only) << "PIEH1234";
  expect_error([&] { read_flo(header_only); }, "8 bytes");
  const std::string missing = path("missing.flo");
  expect_error([&] { read_flo(missing); }, "no such file");
  expect_error([&] { read_flo(dir_.string()); }, "not a regular file");
}

TEST_F(FloIoTest, WriteRejectsWrongTypeAndEmpty) {
  const std::string p = path("bad.flo");
  expect_error([&] { write_flo(p, cv::Mat(2, 2, CV_32FC1, cv::Scalar(0))); }, "CV_32FC1");
  expect_error([&] { write_flo(p, cv::Mat(2, 2, CV_64FC2, cv::Scalar(0))); }, "CV_64FC2");
  expect_error([&] { write_flo(p, cv::Mat()); }, "empty");
  EXPECT_FALSE(fs::exists(p));
  EXPECT_FALSE(fs::exists(p + ".tmp"));
}

TEST_F(FloIoTest, WriteIntoMissingDirectoryThrowsAndLeavesNoFile) {
  const fs::path missing_dir = dir_ / "no_such_dir";
  const std::string p = (missing_dir / "out.flo").string();
  expect_error([&] { write_flo(p, cv::Mat(2, 2, CV_32FC2, cv::Scalar(1, 1))); }, p);
  EXPECT_FALSE(fs::exists(missing_dir));
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(FloIoTest, WriteOntoADirectoryThrowsAndLeavesNoTemporary) {
  // The temporary is written fine; the rename onto a directory fails and must clean up.
  const fs::path target = dir_ / "taken";
  fs::create_directory(target);
  expect_error([&] { write_flo(target.string(), cv::Mat(2, 2, CV_32FC2, cv::Scalar(1, 1))); },
               target.string());
  EXPECT_FALSE(fs::exists(target.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(target));
}

TEST_F(FloIoTest, ParseFloDecodesTheSameBytesAsReadFlo) {
  const std::string p = write_raw("mem.flo", kFloMagic, 4, 3, ramp(4 * 3 * 2));
  std::ifstream in(p, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const cv::Mat from_memory = parse_flo(bytes, "mem");
  const cv::Mat from_file = read_flo(p);
  ASSERT_EQ(from_memory.size(), cv::Size(4, 3));
  EXPECT_EQ(cv::norm(from_memory, from_file, cv::NORM_INF), 0.0);
  EXPECT_FLOAT_EQ(from_memory.at<cv::Vec2f>(2, 3)[1], 0.25f * 23 - 3.f);
}

TEST_F(FloIoTest, ParseFloRejectsLikeReadFloNamingTheInput) {
  expect_error([&] { parse_flo("", "empty input"); }, "empty input");
  expect_error([&] { parse_flo("", "x"); }, "shorter than the 12-byte header");
  expect_error([&] { parse_flo(std::string(12, '\0'), "zeros"); }, "magic");
  std::string header(12, '\0');
  const std::int32_t size[2] = {2, 2};
  std::memcpy(header.data(), &kFloMagic, 4);
  std::memcpy(header.data() + 4, size, 8);
  expect_error([&] { parse_flo(header, "h"); }, "truncated");
  expect_error([&] { parse_flo(header + std::string(33, '\0'), "h"); }, "trailing");
  EXPECT_EQ(parse_flo(header + std::string(32, '\0'), "h").size(), cv::Size(2, 2));
}

}  // namespace
}  // namespace roiflow::eval
