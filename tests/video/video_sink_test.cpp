#include "video/video_sink.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using video::VideoSink;
namespace fs = std::filesystem;

const cv::Size kSinkSize(96, 64);

// A moving bright square on a dark background: something a codec must really encode.
cv::Mat make_frame(int i, cv::Size size = kSinkSize) {
  cv::Mat frame(size, CV_8UC3, cv::Scalar(30, 40, 50));
  frame(cv::Rect((i * 5) % (size.width - 16), 20, 16, 16)).setTo(cv::Scalar(200, 220, 240));
  return frame;
}

struct Decoded {
  int frames = 0;
  cv::Size size;
};

// Counts frames by decoding them all: the container's announced count could hide a truncation.
Decoded decode(const std::string& path) {
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  Decoded result;
  if (!capture.isOpened()) return result;
  cv::Mat frame;
  while (capture.read(frame)) {
    ++result.frames;
    result.size = frame.size();
  }
  return result;
}

class VideoSinkTest : public test::TempDirTest {};

class VideoSinkFormatTest : public VideoSinkTest,
                            public ::testing::WithParamInterface<const char*> {};

TEST_P(VideoSinkFormatTest, RoundTripsEveryFrame) {
  const std::string file = path(std::string("out") + GetParam());
  {
    VideoSink sink(file, 25, kSinkSize);
    for (int i = 0; i < 12; ++i)
      sink.write(make_frame(i));
    EXPECT_EQ(sink.frames(), 12);
    sink.close();
    sink.close();  // idempotent
  }
  const Decoded decoded = decode(file);
  EXPECT_EQ(decoded.frames, 12);
  EXPECT_EQ(decoded.size, kSinkSize);
}

// Test names are the extensions without their dot.
INSTANTIATE_TEST_SUITE_P(VideoSink, VideoSinkFormatTest,
                         ::testing::Values(".avi", ".mp4", ".mkv", ".mov", ".MP4"),
                         [](const ::testing::TestParamInfo<const char*>& extension) {
                           return std::string(extension.param + 1);
                         });

TEST_F(VideoSinkTest, DestructorLeavesAPlayableFile) {
  for (const char* name : {"interrupted.mp4", "interrupted.avi"}) {
    try {
      VideoSink sink(path(name), 10, kSinkSize);
      for (int i = 0; i < 7; ++i)
        sink.write(make_frame(i));
      throw std::runtime_error("the run dies here");
    } catch (const std::runtime_error&) {
    }
    const Decoded decoded = decode(path(name));
    EXPECT_EQ(decoded.frames, 7) << name;
    EXPECT_EQ(decoded.size, kSinkSize) << name;
  }
}

TEST_F(VideoSinkTest, GrayFramesAreConvertedToBgr) {
  {
    VideoSink sink(path("gray.avi"), 25, kSinkSize);
    cv::Mat gray;
    cv::extractChannel(make_frame(1), gray, 0);
    sink.write(gray);
    sink.write(make_frame(2));
  }
  EXPECT_EQ(decode(path("gray.avi")).frames, 2);
}

TEST_F(VideoSinkTest, PngFolderHoldsNumberedWholeFrames) {
  const std::string folder = path("frames");
  VideoSink sink(folder, 25, kSinkSize);
  EXPECT_TRUE(fs::is_directory(folder));
  cv::Mat gray(kSinkSize, CV_8UC1, cv::Scalar(77));
  sink.write(make_frame(0));
  sink.write(make_frame(1));
  sink.write(gray);
  sink.close();
  EXPECT_EQ(sink.frames(), 3);

  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"000001.png", "000002.png", "000003.png"}));

  const cv::Mat second = cv::imread(folder + "/000002.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(second.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(second, make_frame(1), cv::NORM_INF), 0.0) << "PNG is lossless";
  const cv::Mat third = cv::imread(folder + "/000003.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(third.type(), CV_8UC3);
  EXPECT_EQ(third.at<cv::Vec3b>(5, 5), cv::Vec3b(77, 77, 77));
}

TEST_F(VideoSinkTest, EncodedOnOtherThreadsThenWrittenInOrder) {
  // Folder: encode() makes the PNG bytes; video: the BGR frame. Either way write_encoded()
  // writes them in its own order, whatever order the encodings finished in.
  for (const std::string name : {"frames", "out.avi"}) {
    SCOPED_TRACE(name);
    VideoSink sink(path(name), 25, kSinkSize);
    std::vector<cv::Mat> encoded(4);
    std::vector<std::thread> threads;
    for (int i = 3; i >= 0; --i)
      threads.emplace_back([&, i] { encoded[i] = sink.encode(make_frame(i)); });
    for (std::thread& t : threads)
      t.join();
    for (const cv::Mat& e : encoded)
      sink.write_encoded(e);
    sink.close();
    EXPECT_EQ(sink.frames(), 4);
    if (name == "frames") {
      EXPECT_EQ(encoded[0].type(), CV_8UC1);
      for (int i = 0; i < 4; ++i) {
        const cv::Mat back = cv::imread(path(name) + "/00000" + std::to_string(i + 1) + ".png",
                                        cv::IMREAD_UNCHANGED);
        ASSERT_FALSE(back.empty());
        EXPECT_EQ(cv::norm(back, make_frame(i), cv::NORM_INF), 0.0) << i;
      }
    } else {
      EXPECT_EQ(decode(path(name)).frames, 4);
    }
  }
  // What encode() made for a folder is not a video frame, and the reverse.
  VideoSink folder(path("f2"), 25, kSinkSize), video(path("v2.avi"), 25, kSinkSize);
  EXPECT_THROW(video.write_encoded(folder.encode(make_frame(0))), Error);
  EXPECT_THROW(folder.write_encoded(video.encode(make_frame(0))), Error);
  EXPECT_THROW(folder.encode(cv::Mat(32, 32, CV_8UC3, cv::Scalar::all(0))), Error);
  EXPECT_EQ(folder.frames(), 0);
}

TEST_F(VideoSinkTest, TrailingSlashOrExistingDirectoryMeansAFolder) {
  VideoSink slash(path("out.png") + "/", 25, kSinkSize);
  slash.write(make_frame(0));
  EXPECT_TRUE(fs::exists(path("out.png/000001.png")));

  fs::create_directory(path("run.v2"));
  VideoSink existing(path("run.v2"), 25, kSinkSize);
  existing.write(make_frame(0));
  EXPECT_TRUE(fs::exists(path("run.v2/000001.png")));
  EXPECT_NE(existing.description().find("PNG frames in '" + path("run.v2") + "'"),
            std::string::npos)
      << existing.description();
}

TEST_F(VideoSinkTest, DescriptionNamesPathCodecAndSize) {
  VideoSink sink(path("a.mp4"), 12.5, kSinkSize);
  EXPECT_EQ(sink.description(), "video '" + path("a.mp4") + "' (mp4v, 12.5 fps, 96x64)");
}

TEST_F(VideoSinkTest, UnknownExtensionThrows) {
  const std::string message =
      test::error_message([&] { VideoSink sink(path("out.jpg"), 25, kSinkSize); });
  EXPECT_NE(message.find("'.jpg'"), std::string::npos) << message;
  EXPECT_NE(message.find(path("out.jpg")), std::string::npos) << message;
}

TEST_F(VideoSinkTest, MissingDirectoryThrowsNamingThePath) {
  const std::string file = path("missing/out.avi");
  const std::string message = test::error_message([&] { VideoSink sink(file, 25, kSinkSize); });
  EXPECT_NE(message.find(file), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(path("missing")));
}

TEST_F(VideoSinkTest, FolderThatCannotBeCreatedThrows) {
  std::ofstream(path("plain_file")) << "x";
  const std::string folder = path("plain_file/frames");
  const std::string message = test::error_message([&] { VideoSink sink(folder, 25, kSinkSize); });
  EXPECT_NE(message.find(folder), std::string::npos) << message;
}

TEST_F(VideoSinkTest, BadParametersThrow) {
  EXPECT_NE(test::error_message([&] { VideoSink sink(path("a.avi"), 0, kSinkSize); }).find("fps"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] {
              VideoSink sink(path("a.avi"), 25, {0, 10});
            }).find("0x10"),
            std::string::npos);
}

TEST_F(VideoSinkTest, BadFramesThrowAndWriteNothing) {
  for (const char* name : {"bad.avi", "bad_frames"}) {
    VideoSink sink(path(name), 25, kSinkSize);
    sink.write(make_frame(0));
    const std::string wrong_size = test::error_message([&] {
      sink.write(make_frame(1, {64, 96}));
    });
    EXPECT_NE(wrong_size.find("64x96"), std::string::npos) << wrong_size;
    EXPECT_NE(wrong_size.find("96x64"), std::string::npos) << wrong_size;
    EXPECT_NE(test::error_message([&] { sink.write(cv::Mat(kSinkSize, CV_32FC3)); }).find("32FC3"),
              std::string::npos);
    EXPECT_NE(test::error_message([&] { sink.write(cv::Mat()); }).find("empty"), std::string::npos);
    EXPECT_EQ(sink.frames(), 1);
    sink.close();
    EXPECT_NE(test::error_message([&] { sink.write(make_frame(2)); }).find("close"),
              std::string::npos);
  }
  EXPECT_EQ(decode(path("bad.avi")).frames, 1);
}

TEST_F(VideoSinkTest, MovedSinkKeepsWriting) {
  VideoSink first(path("moved.avi"), 25, kSinkSize);
  first.write(make_frame(0));
  VideoSink second = std::move(first);
  second.write(make_frame(1));
  EXPECT_EQ(second.frames(), 2);
  second.close();
  EXPECT_EQ(decode(path("moved.avi")).frames, 2);
}

}  // namespace
