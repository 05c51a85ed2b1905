#include "video/video_source.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace roiflow::video {
namespace {

namespace fs = std::filesystem;
using roiflow::test::error_message;
using State = SourceStatus::State;

const cv::Size kSize(64, 48);
constexpr int kSourceFrames = 10;

// A textured background with a bright square that moves 4 px right per frame, so the order of
// frames can be read back from the square's position.
cv::Mat source_frame(int k, cv::Size size = kSize) {
  cv::Mat image(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(20 + (x * 7 + y * 3) % 40),
                                            static_cast<uchar>(30 + (x * 5) % 30), 40);
  cv::rectangle(image, cv::Rect(4 + 4 * k, 16, 12, 12), cv::Scalar(255, 255, 255), cv::FILLED);
  return image;
}

// The x coordinate of the square's centre in a frame.
double square_x(const cv::Mat& gray) {
  const cv::Moments m = cv::moments(gray > 160, true);
  return m.m00 > 0 ? m.m10 / m.m00 : -1;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Everything the source delivers, but never more than `limit` frames: a source that does not
// end fails the test instead of hanging it.
std::vector<Frame> read_all(VideoSource& source, int limit = 2 * kSourceFrames) {
  std::vector<Frame> frames;
  while (static_cast<int>(frames.size()) <= limit) {
    auto frame = source.next();
    if (!frame) break;
    frames.push_back(std::move(*frame));
  }
  EXPECT_LE(static_cast<int>(frames.size()), limit) << "the source did not end";
  return frames;
}

// Indices first..first+n-1 in order, gray 8-bit of kSize, the square moving right.
void expect_in_order(const std::vector<Frame>& frames, long long first, int n) {
  ASSERT_EQ(static_cast<int>(frames.size()), n);
  for (int i = 0; i < n; ++i) {
    const Frame& frame = frames[static_cast<std::size_t>(i)];
    EXPECT_EQ(frame.index, first + i);
    EXPECT_EQ(frame.gray.type(), CV_8UC1);
    EXPECT_EQ(frame.gray.size(), kSize);
    EXPECT_EQ(frame.picture().size(), kSize);
    EXPECT_NEAR(square_x(frame.gray), 4 + 4 * frame.index + 5.5, 1.0) << "frame " << i;
    if (i > 0) {
      EXPECT_GT(frame.timestamp_s, frames[static_cast<std::size_t>(i) - 1].timestamp_s);
    }
  }
}

// Indices first..first+n-1, in order.
void expect_indices(const std::vector<Frame>& frames, long long first, int n) {
  ASSERT_EQ(static_cast<int>(frames.size()), n);
  for (int i = 0; i < n; ++i)
    EXPECT_EQ(frames[static_cast<std::size_t>(i)].index, first + i);
}

class VideoSourceTest : public roiflow::test::TempDirTest {
 protected:
  std::string write_video(const std::string& name = "clip.avi", int n = kSourceFrames) {
    const std::string file = path(name);
    cv::VideoWriter writer(file, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25,
                           kSize);
    EXPECT_TRUE(writer.isOpened()) << "this OpenCV build cannot write MJPG into .avi";
    for (int k = 0; k < n; ++k)
      writer.write(source_frame(k));
    return file;
  }

  // Frames first..first+n-1 of source_frame() as dir/<printf(format, number)>, numbers from 1.
  void write_images(const std::string& dir, const char* format, int n = kSourceFrames) {
    fs::create_directories(path(dir));
    for (int k = 0; k < n; ++k)
      ASSERT_TRUE(cv::imwrite(image_path(dir, format, k + 1), source_frame(k)));
  }

  std::string image_path(const std::string& dir, const char* format, int number) const {
    char name[64];
    std::snprintf(name, sizeof name, format, number);
    return path(dir + "/" + name);
  }
};

TEST_F(VideoSourceTest, ReadsVideoFileInOrderWithIncreasingTimestamps) {
  const std::string file = write_video();
  VideoSource source(file);
  EXPECT_EQ(source.size(), kSize);
  EXPECT_DOUBLE_EQ(source.fps(), 25);
  EXPECT_EQ(source.frame_count_hint(), kSourceFrames);
  EXPECT_NE(source.description().find(file), std::string::npos) << source.description();
  EXPECT_EQ(source.status().state, State::kStreaming);

  const auto frames = read_all(source);
  expect_in_order(frames, 0, kSourceFrames);
  for (const Frame& frame : frames) {
    EXPECT_EQ(frame.image.type(), CV_8UC3);
    EXPECT_NEAR(frame.timestamp_s, frame.index / 25.0, 0.5 / 25);
  }
  EXPECT_EQ(source.status().state, State::kEnded);
  EXPECT_EQ(source.status().message, "end of stream");
  EXPECT_FALSE(source.next());
}

// defer_colour: a video's frames carry their picture deferred, equal to the one read at once;
// other inputs (an image folder here) ignore it.
TEST_F(VideoSourceTest, DeferredColourGivesTheSamePicturesWhenAsked) {
  const std::string file = write_video();
  VideoSource eager(file);
  VideoSourceParams params;
  params.defer_colour = true;
  VideoSource deferred(file, params);
  EXPECT_EQ(deferred.size(), kSize);
  const auto a = read_all(eager);
  const auto b = read_all(deferred);
  expect_in_order(b, 0, kSourceFrames);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(b[i].image.empty());
    ASSERT_TRUE(b[i].deferred_image);
    const cv::Mat picture = b[i].picture();
    ASSERT_EQ(picture.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(picture, a[i].image, cv::NORM_INF), 0) << "frame " << i;
    EXPECT_EQ(cv::norm(b[i].gray, a[i].gray, cv::NORM_INF), 0) << "frame " << i;
    EXPECT_EQ(a[i].picture().data, a[i].image.data);  // nothing deferred: the image itself
  }

  write_images("seq", "%04d.png");
  VideoSource folder(path("seq"), params);
  const auto frame = folder.next();
  ASSERT_TRUE(frame);
  EXPECT_FALSE(frame->deferred_image);
  EXPECT_EQ(frame->image.type(), CV_8UC3);
}

TEST_F(VideoSourceTest, ReadsOtbFolderAtTheGivenFps) {
  write_images("Car/img", "%04d.jpg");
  write_bytes(path("Car/groundtruth_rect.txt"), "1,2,3,4\n");
  VideoSource source(path("Car"), {.fps = 10});
  EXPECT_EQ(source.frame_count_hint(), kSourceFrames);
  EXPECT_DOUBLE_EQ(source.fps(), 10);
  EXPECT_NE(source.description().find("0001.jpg"), std::string::npos) << source.description();

  const auto frames = read_all(source);
  expect_in_order(frames, 0, kSourceFrames);
  for (const Frame& frame : frames)
    EXPECT_DOUBLE_EQ(frame.timestamp_s, frame.index / 10.0);
  EXPECT_EQ(source.status().state, State::kEnded);
}

TEST_F(VideoSourceTest, SortsUnpaddedNumbersNumericallyAndKeepsGrayImagesGray) {
  fs::create_directories(path("seq"));
  for (int k = 0; k < 12; ++k) {
    cv::Mat gray;
    cv::cvtColor(source_frame(k), gray, cv::COLOR_BGR2GRAY);
    ASSERT_TRUE(cv::imwrite(image_path("seq", "%d.png", k + 1), gray));
  }
  write_bytes(path("seq/notes9.txt"), "not a frame");
  VideoSource source(path("seq"));
  const auto frames = read_all(source);
  expect_in_order(frames, 0, 12);
  EXPECT_EQ(frames[0].image.type(), CV_8UC1);
  EXPECT_EQ(frames[0].gray.data, frames[0].image.data);
}

TEST_F(VideoSourceTest, ReadsPrintfPattern) {
  write_images("frames", "f_%03d.png");
  write_images("frames", "other_%03d.png", 2);
  VideoSource source(path("frames/f_%03d.png"));
  EXPECT_EQ(source.frame_count_hint(), kSourceFrames);
  expect_in_order(read_all(source), 0, kSourceFrames);
  EXPECT_EQ(source.status().state, State::kEnded);
}

TEST_F(VideoSourceTest, UnreadableInputsThrowNamingThePath) {
  const std::string missing = path("nope.mp4");
  EXPECT_NE(error_message([&] { VideoSource s(missing); }).find(missing), std::string::npos);

  const std::string empty = path("empty.avi");
  write_bytes(empty, "");
  EXPECT_NE(error_message([&] { VideoSource s(empty); }).find(empty), std::string::npos);

  const std::string random = path("random.mp4");
  cv::Mat noise(1, 20000, CV_8UC1);
  cv::randu(noise, 0, 256);
  write_bytes(random, std::string(noise.ptr<char>(), noise.total()));
  EXPECT_NE(error_message([&] { VideoSource s(random); }).find(random), std::string::npos);

  const std::string no_images = path("docs");
  fs::create_directories(no_images + "/img");
  write_bytes(no_images + "/readme.txt", "text");
  EXPECT_NE(error_message([&] { VideoSource s(no_images); }).find(no_images), std::string::npos);

  const std::string no_match = path("docs/%04d.jpg");
  EXPECT_NE(error_message([&] { VideoSource s(no_match); }).find(no_match), std::string::npos);
  const std::string bad_pattern = path("docs/%s.jpg");
  EXPECT_NE(error_message([&] { VideoSource s(bad_pattern); }).find(bad_pattern),
            std::string::npos);
}

TEST_F(VideoSourceTest, CorruptFirstImageThrowsNamingTheFile) {
  write_images("seq", "%04d.jpg", 3);
  write_bytes(image_path("seq", "%04d.jpg", 1), "garbage, not a jpeg");
  const std::string message = error_message([&] { VideoSource s(path("seq")); });
  EXPECT_NE(message.find(image_path("seq", "%04d.jpg", 1)), std::string::npos) << message;
}

TEST_F(VideoSourceTest, TruncatedVideoThrowsOrStopsEarlyWithAReason) {
  const std::string bytes = read_bytes(write_video());
  const std::string truncated = path("truncated.avi");
  write_bytes(truncated, bytes.substr(0, bytes.size() * 2 / 5));
  try {
    VideoSource source(truncated);
    const auto frames = read_all(source, kSourceFrames);
    EXPECT_LT(static_cast<int>(frames.size()), kSourceFrames);
    EXPECT_EQ(source.status().state, State::kStopped);
    EXPECT_NE(source.status().message.find("stopped at frame " + std::to_string(frames.size())),
              std::string::npos)
        << source.status().message;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(truncated), std::string::npos) << e.what();
  }
}

TEST_F(VideoSourceTest, GapInNumberingStopsThereNamingTheMissingFile) {
  write_images("seq/img", "%04d.jpg");
  fs::remove(image_path("seq/img", "%04d.jpg", 5));
  VideoSource source(path("seq"));
  EXPECT_EQ(source.frame_count_hint(), 4);
  expect_in_order(read_all(source), 0, 4);
  EXPECT_EQ(source.status().state, State::kStopped);
  const std::string& message = source.status().message;
  EXPECT_EQ(message.rfind("stopped at frame 4: ", 0), 0u) << message;
  EXPECT_NE(message.find(image_path("seq/img", "%04d.jpg", 5)), std::string::npos) << message;
}

TEST_F(VideoSourceTest, CorruptImageStopsThereWithTheReason) {
  write_images("seq", "%04d.jpg");
  write_bytes(image_path("seq", "%04d.jpg", 6), "garbage, not a jpeg");
  VideoSource source(path("seq"));
  expect_in_order(read_all(source), 0, 5);
  EXPECT_EQ(source.status().state, State::kStopped);
  const std::string& message = source.status().message;
  EXPECT_EQ(message.rfind("stopped at frame 5: cannot decode", 0), 0u) << message;
  EXPECT_NE(message.find(image_path("seq", "%04d.jpg", 6)), std::string::npos) << message;
}

TEST_F(VideoSourceTest, FrameOfAnotherSizeStopsThereWithTheReason) {
  write_images("seq", "%04d.png");
  ASSERT_TRUE(cv::imwrite(image_path("seq", "%04d.png", 3), source_frame(2, cv::Size(32, 24))));
  VideoSource source(path("seq"));
  expect_in_order(read_all(source), 0, 2);
  EXPECT_EQ(source.status().state, State::kStopped);
  EXPECT_EQ(source.status().message,
            "stopped at frame 2: frame size 32x24 differs from the first frame's 64x48");
}

TEST_F(VideoSourceTest, StartAndMaxFramesSelectARange) {
  write_images("seq", "%04d.jpg");
  VideoSource folder(path("seq"), {.start = 3, .max_frames = 4});
  EXPECT_EQ(folder.frame_count_hint(), 4);
  const auto from_folder = read_all(folder);
  expect_in_order(from_folder, 3, 4);
  EXPECT_DOUBLE_EQ(from_folder[0].timestamp_s, 3 / 25.0);
  EXPECT_EQ(folder.status().state, State::kEnded);

  const std::string file = write_video();
  VideoSource whole(file);
  const auto all = read_all(whole);
  VideoSource video(file, {.start = 2, .max_frames = 3});
  EXPECT_EQ(video.frame_count_hint(), 3);
  const auto part = read_all(video);
  expect_in_order(part, 2, 3);
  EXPECT_EQ(video.status().state, State::kEnded);
  for (const Frame& frame : part)
    EXPECT_EQ(cv::norm(frame.gray, all[static_cast<std::size_t>(frame.index)].gray, cv::NORM_INF),
              0);

  const std::string message = error_message([&] { VideoSource s(file, {.start = kSourceFrames}); });
  EXPECT_NE(message.find(file), std::string::npos) << message;
  EXPECT_NE(message.find("start 10"), std::string::npos) << message;
}

TEST_F(VideoSourceTest, BadParamsThrowNamingTheValue) {
  write_images("seq", "%04d.jpg", 2);
  EXPECT_NE(error_message([&] { VideoSource s(path("seq"), {.fps = 0}); }).find("got 0"),
            std::string::npos);
  EXPECT_NE(error_message([&] { VideoSource s(path("seq"), {.start = -1}); }).find("got -1"),
            std::string::npos);
  EXPECT_NE(error_message([&] { VideoSource s(path("seq"), {.max_frames = -2}); }).find("got -2"),
            std::string::npos);
}

TEST_F(VideoSourceTest, SyntheticStreamDeliversExactlyNFramesInOrder) {
  VideoSource source("synthetic:700:96x72", {.fps = 50});
  EXPECT_EQ(source.size(), cv::Size(96, 72));
  EXPECT_EQ(source.frame_count_hint(), 700);
  EXPECT_DOUBLE_EQ(source.fps(), 50);
  EXPECT_NE(source.description().find("synthetic scene (700 frames"), std::string::npos)
      << source.description();
  const std::vector<Frame> frames = read_all(source, 700);
  ASSERT_EQ(frames.size(), 700u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(frames[i].index, static_cast<long long>(i));
    EXPECT_DOUBLE_EQ(frames[i].timestamp_s, static_cast<double>(i) / 50);
    EXPECT_EQ(frames[i].image.type(), CV_8UC3);
    EXPECT_EQ(frames[i].gray.type(), CV_8UC1);
  }
  EXPECT_EQ(source.status().state, State::kEnded);
  // The 300-frame scene plays forwards then backwards: frame 300 shows scene frame 298, frame
  // 598 scene frame 0 again; neighbours differ (the vehicle moves, the noise changes).
  const auto same = [&](std::size_t a, std::size_t b) {
    return cv::norm(frames[a].image, frames[b].image, cv::NORM_INF) == 0;
  };
  EXPECT_TRUE(same(300, 298));
  EXPECT_TRUE(same(598, 0));
  EXPECT_TRUE(same(599, 1));
  EXPECT_FALSE(same(1, 0));
  EXPECT_FALSE(same(299, 298));
}

TEST_F(VideoSourceTest, SyntheticStreamHonoursStartAndMaxFrames) {
  VideoSource source("synthetic:50:64x64", {.start = 10, .max_frames = 5});
  EXPECT_EQ(source.frame_count_hint(), 5);
  expect_indices(read_all(source), 10, 5);
  VideoSource defaults("synthetic:3");
  EXPECT_EQ(defaults.size(), cv::Size(640, 480));
}

TEST_F(VideoSourceTest, MalformedSyntheticInputThrowsNamingIt) {
  for (const char* input :
       {"synthetic:", "synthetic:0", "synthetic:-3", "synthetic:12x",
        "synthetic:5:", "synthetic:5:640", "synthetic:5:32x32", "synthetic:5:9000x100",
        "synthetic:5:640x480x2", "synthetic:2000000000"}) {
    const std::string message = error_message([&] { VideoSource s(input); });
    EXPECT_NE(message.find(std::string("bad synthetic input '") + input + "'"), std::string::npos)
        << message;
  }
  // An existing file of that name is read as the file it is.
  write_bytes(path("synthetic:5"), "not a video");
  const std::string message = error_message([&] { VideoSource s(path("synthetic:5")); });
  EXPECT_NE(message.find("cannot open video"), std::string::npos) << message;
}

TEST_F(VideoSourceTest, FirstFrameOutOfTheSizeLimitsThrowsNamingTheSize) {
  fs::create_directories(path("tiny"));
  ASSERT_TRUE(cv::imwrite(path("tiny/1.png"), cv::Mat(1, 1, CV_8UC1, cv::Scalar(3))));
  const std::string message = error_message([&] { VideoSource s(path("tiny")); });
  EXPECT_NE(message.find("1x1: smaller than the minimum"), std::string::npos) << message;
}

}  // namespace
}  // namespace roiflow::video
