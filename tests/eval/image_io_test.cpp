#include "eval/image_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;
using roiflow::test::error_message;

const cv::Size kImageSize(64, 48);

// A textured picture with a bright square.
cv::Mat scene(cv::Size size = kImageSize) {
  cv::Mat image(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(20 + (x * 7 + y * 3) % 40),
                                            static_cast<uchar>(30 + (x * 5) % 30), 40);
  cv::rectangle(image, cv::Rect(8, 16, 12, 12), cv::Scalar(255, 255, 255), cv::FILLED);
  return image;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ImageIoTest : public roiflow::test::TempDirTest {
 protected:
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
};

TEST_F(ImageIoTest, FrameSizeLimits) {
  EXPECT_NO_THROW(check_frame_size({kMinFrameSide, kMinFrameSide}, "x"));
  EXPECT_NO_THROW(check_frame_size({kMaxFrameSide, 4000}, "x"));  // 32.8 Mpixel
  EXPECT_NO_THROW(check_frame_size({7680, 4320}, "x"));           // 8K UHD
  const std::string tiny = error_message([] { check_frame_size({11, 500}, "image 'a.png'"); });
  EXPECT_EQ(tiny, "image 'a.png' is 11x500: smaller than the minimum of 12 px a side");
  EXPECT_NE(error_message([] {
              check_frame_size({kMaxFrameSide + 1, 20}, "x");
            }).find("8193x20"),
            std::string::npos);
  EXPECT_NE(error_message([] {
              check_frame_size({8000, 6000}, "x");
            }).find("40 Mpixel"),
            std::string::npos);  // each side fits, the area does not
}

TEST_F(ImageIoTest, ReadImageRefusesCutOrDamagedPngAndJpeg) {
  ASSERT_TRUE(cv::imwrite(path("a.png"), scene()));
  ASSERT_TRUE(cv::imwrite(path("a.jpg"), scene()));
  EXPECT_EQ(read_image(path("a.png"), cv::IMREAD_ANYCOLOR).size(), kImageSize);
  EXPECT_EQ(read_image(path("a.jpg"), cv::IMREAD_GRAYSCALE).type(), CV_8UC1);
  // Trailing bytes after the end of a JPEG (some cameras append data) are fine.
  write_bytes(path("tail.jpg"), read_bytes(path("a.jpg")) + "trailer");
  EXPECT_EQ(read_image(path("tail.jpg"), cv::IMREAD_ANYCOLOR).size(), kImageSize);

  const std::string png = read_bytes(path("a.png"));
  const std::string jpg = read_bytes(path("a.jpg"));
  const struct {
    std::string name, bytes, expected;
  } cases[] = {
      {"cut.png", png.substr(0, png.size() - 5), "truncated PNG"},
      {"half.png", png.substr(0, png.size() / 2), "truncated PNG"},
      {"chunk.png", png.substr(0, 12) + "\x01\x02\x03\x04" + png.substr(16), "damaged PNG"},
      {"cut.jpg", jpg.substr(0, jpg.size() - 2), "truncated JPEG"},
      {"half.jpg", jpg.substr(0, jpg.size() / 2), "truncated JPEG"},
      {"empty.png", "", "empty file"},
      {"text.png", "not an image", "cannot decode image"},
  };
  for (const auto& c : cases) {
    write_bytes(path(c.name), c.bytes);
    const std::string message =
        error_message([&] { read_image(path(c.name), cv::IMREAD_ANYCOLOR); });
    EXPECT_EQ(message.rfind("cannot decode image '" + path(c.name) + "'", 0), 0u) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
  }
  EXPECT_NE(error_message([&] { read_image(path("none.png"), 0); }).find("cannot open image"),
            std::string::npos);
}

TEST_F(ImageIoTest, ImageRoundTripsInTheFormatOfTheExtension) {
  cv::Mat image(12, 17, CV_8UC3);
  cv::randu(image, 0, 256);
  write_image_atomically(path("frame.png"), image);
  const cv::Mat back = cv::imread(path("frame.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  EXPECT_EQ(files(), std::vector<std::string>{"frame.png"});
}

TEST_F(ImageIoTest, ImageWithUnknownExtensionThrows) {
  const std::string target = path("frame.nosuchformat");
  EXPECT_EQ(test::error_message([&] { write_image_atomically(target, cv::Mat(4, 4, CV_8UC1)); }),
            "cannot write image '" + target + "'");
  EXPECT_TRUE(files().empty());
}

}  // namespace
}  // namespace roiflow::eval
