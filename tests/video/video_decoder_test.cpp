#include "video/video_decoder.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "test_util.hpp"

namespace roiflow::video {
namespace {

using roiflow::test::error_message;

const cv::Size kDecoderSize(160, 120);
constexpr int kFrames = 12;

// Colourful texture (every channel varies, within 30..220 so that no colour is clipped in the
// codec's round trip, where the BGR frame's gray would part from the luma) with a light square
// moving 3 px a frame.
cv::Mat decoder_frame(int k) {
  cv::Mat image(kDecoderSize, CV_8UC3);
  for (int y = 0; y < kDecoderSize.height; ++y)
    for (int x = 0; x < kDecoderSize.width; ++x)
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(30 + (x * 7 + y * 3) % 150),
                                            static_cast<uchar>(30 + (x * 2 + y * 5) % 150),
                                            static_cast<uchar>(30 + (y * 11) % 150));
  cv::rectangle(image, cv::Rect(10 + 3 * k, 40, 20, 20), cv::Scalar(220, 215, 210), cv::FILLED);
  return image;
}

struct Codec {
  const char* name;
  const char* file;
  int fourcc;
};

class VideoDecoderTest : public roiflow::test::TempDirTest,
                         public ::testing::WithParamInterface<Codec> {
 protected:
  std::string write_video() {
    const Codec& codec = GetParam();
    const std::string file = path(codec.file);
    cv::VideoWriter writer(file, cv::CAP_FFMPEG, codec.fourcc, 25, kDecoderSize);
    EXPECT_TRUE(writer.isOpened()) << "cannot write " << codec.name;
    for (int k = 0; k < kFrames; ++k)
      writer.write(decoder_frame(k));
    return file;
  }
};

// MJPG decodes to full-range YUV (yuvj420p), MPEG-4 to video range (yuv420p): the gray frame
// is the luma plane as it is in the first case and expanded in the second; in both it must be
// the BGR frame's own gray, within rounding.
TEST_P(VideoDecoderTest, GrayIsTheBgrFramesGrayAndFramesComeInOrder) {
  VideoDecoder video(write_video());
  EXPECT_EQ(video.size(), kDecoderSize);
  EXPECT_DOUBLE_EQ(video.fps(), 25);
  EXPECT_EQ(video.frame_count(), kFrames);
  EXPECT_EQ(video.threads(), 1);  // small frames: one decoder thread
  DecodedFrame f;
  std::string failure;
  int n = 0;
  double last_timestamp = -1;
  while (video.read(f, failure)) {
    ASSERT_EQ(f.bgr.type(), CV_8UC3);
    ASSERT_EQ(f.gray.type(), CV_8UC1);
    ASSERT_EQ(f.gray.size(), kDecoderSize);
    // Near the BGR frame's gray (which differs by swscale's rounding, up to one level biased
    // at full range, and where interpolated chroma overshoots and a colour is clipped), and at
    // least as near the original picture's gray as that one.
    cv::Mat from_bgr, original;
    cv::cvtColor(f.bgr, from_bgr, cv::COLOR_BGR2GRAY);
    cv::cvtColor(decoder_frame(n), original, cv::COLOR_BGR2GRAY);
    const auto mean_diff = [](const cv::Mat& a, const cv::Mat& b) {
      cv::Mat diff;
      cv::absdiff(a, b, diff);
      return cv::mean(diff)[0];
    };
    EXPECT_LT(mean_diff(f.gray, from_bgr), 2.0) << GetParam().name << " frame " << n;
    EXPECT_LE(mean_diff(f.gray, original), mean_diff(from_bgr, original) + 0.2)
        << GetParam().name << " frame " << n << ": " << mean_diff(f.gray, original) << " vs "
        << mean_diff(from_bgr, original);
    // The square (bright in gray) moved 3 px a frame.
    const cv::Moments m = cv::moments(f.gray(cv::Rect(0, 40, kDecoderSize.width, 20)) > 200, true);
    ASSERT_GT(m.m00, 0);
    EXPECT_NEAR(m.m10 / m.m00, 10 + 3 * n + 9.5, 1.5) << "frame " << n;
    EXPECT_NEAR(f.timestamp_s, n / 25.0, 0.5 / 25);
    EXPECT_GT(f.timestamp_s, last_timestamp);
    last_timestamp = f.timestamp_s;
    ++n;
  }
  EXPECT_EQ(failure, "");
  EXPECT_EQ(n, kFrames);
  EXPECT_FALSE(video.read(f, failure));
}

// Buffers come back once nobody holds them, and a frame still held is never written over.
TEST_P(VideoDecoderTest, BuffersAreRecycledButNeverWhileHeld) {
  VideoDecoder video(write_video());
  std::string failure;
  DecodedFrame held;
  ASSERT_TRUE(video.read(held, failure));
  const cv::Mat held_bgr = held.bgr.clone();
  const cv::Mat held_gray = held.gray.clone();
  std::vector<const uchar*> seen;
  for (int k = 1; k < kFrames; ++k) {
    DecodedFrame f;
    ASSERT_TRUE(video.read(f, failure)) << failure;
    EXPECT_NE(f.bgr.data, held.bgr.data);
    EXPECT_NE(f.gray.data, held.gray.data);
    seen.push_back(f.gray.data);
  }
  EXPECT_EQ(cv::norm(held.bgr, held_bgr, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(held.gray, held_gray, cv::NORM_INF), 0);
  // Each frame was let go before the next was read: one buffer served them all.
  for (const uchar* data : seen)
    EXPECT_EQ(data, seen.front());
}

// With defer_bgr, the BGR picture is made on request, from any thread, after the decoder is
// gone, and equals the one made at once, bit for bit; pictures held at once never share a buffer.
TEST_P(VideoDecoderTest, DeferredBgrEqualsTheEagerOneFromAnyThreadAfterTheDecoderIsGone) {
  const std::string file = write_video();
  std::vector<cv::Mat> eager_bgr, eager_gray;
  {
    VideoDecoder video(file);
    DecodedFrame f;
    std::string failure;
    while (video.read(f, failure)) {
      EXPECT_FALSE(f.deferred_bgr);
      eager_bgr.push_back(f.bgr.clone());
      eager_gray.push_back(f.gray.clone());
    }
  }
  ASSERT_EQ(static_cast<int>(eager_bgr.size()), kFrames);

  std::vector<DecodedFrame> frames;
  {
    VideoDecoder video(file, 0, true);
    DecodedFrame f;
    std::string failure;
    while (video.read(f, failure)) {
      EXPECT_TRUE(f.bgr.empty());
      ASSERT_TRUE(f.deferred_bgr);
      frames.push_back(f);
      f = DecodedFrame();  // the next read gets fresh buffers
    }
    EXPECT_EQ(failure, "");
  }
  ASSERT_EQ(frames.size(), eager_bgr.size());

  // Four threads ask for every picture at once, in different orders.
  constexpr int kThreads = 4;
  std::vector<std::vector<cv::Mat>> got(kThreads, std::vector<cv::Mat>(frames.size()));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (std::size_t k = 0; k < frames.size(); ++k) {
        const std::size_t i = t % 2 == 0 ? k : frames.size() - 1 - k;
        got[static_cast<std::size_t>(t)][i] = frames[i].deferred_bgr->get();
      }
    });
  }
  for (std::thread& thread : threads)
    thread.join();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat& bgr = got[0][i];
    ASSERT_EQ(bgr.type(), CV_8UC3);
    ASSERT_EQ(bgr.size(), kDecoderSize);
    EXPECT_EQ(cv::norm(bgr, eager_bgr[i], cv::NORM_INF), 0) << "frame " << i;
    EXPECT_EQ(cv::norm(frames[i].gray, eager_gray[i], cv::NORM_INF), 0) << "frame " << i;
    for (int t = 1; t < kThreads; ++t)
      EXPECT_EQ(got[static_cast<std::size_t>(t)][i].data, bgr.data) << "made twice: frame " << i;
    for (std::size_t j = 0; j < i; ++j)
      EXPECT_NE(got[0][j].data, bgr.data) << "frames " << j << " and " << i << " share a buffer";
  }
}

// A DeferredImage is made once whoever asks, and a maker that throws leaves it to the next call.
TEST(DeferredImageTest, MadeOnceAcrossThreadsAndRetriedAfterAFailure) {
  std::atomic<int> made{0};
  const DeferredImage once([&] {
    ++made;
    return cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3));
  });
  std::vector<std::thread> threads;
  std::vector<cv::Mat> got(8);
  for (std::size_t t = 0; t < got.size(); ++t)
    threads.emplace_back([&, t] { got[t] = once.get(); });
  for (std::thread& thread : threads)
    thread.join();
  EXPECT_EQ(made.load(), 1);
  for (const cv::Mat& m : got)
    EXPECT_EQ(m.data, got.front().data);

  int calls = 0;
  const DeferredImage flaky([&] {
    if (++calls == 1) throw std::runtime_error("first call fails");
    return cv::Mat(2, 2, CV_8UC1, cv::Scalar(9));
  });
  EXPECT_THROW(flaky.get(), std::runtime_error);
  EXPECT_EQ(flaky.get().at<uchar>(1, 1), 9);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(picture_of(cv::Mat(), nullptr, cv::Mat(3, 3, CV_8UC1)).rows, 3);  // gray at last
}

std::string codec_name(const ::testing::TestParamInfo<Codec>& codec) {
  return codec.param.name == std::string("MJPG") ? "Mjpg" : "Mpeg4";
}

INSTANTIATE_TEST_SUITE_P(
    Codecs, VideoDecoderTest,
    ::testing::Values(Codec{"MJPG", "clip.avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G')},
                      Codec{"MPEG-4", "clip.mp4", cv::VideoWriter::fourcc('m', 'p', '4', 'v')}),
    codec_name);

class VideoDecoderErrorTest : public roiflow::test::TempDirTest {};

TEST_F(VideoDecoderErrorTest, BadInputsThrowNamingTheFile) {
  const std::string missing = path("missing.mp4");
  EXPECT_NE(error_message([&] { VideoDecoder v(missing); }).find(missing), std::string::npos);
  const std::string text = path("notes.mp4");
  std::ofstream(text) << "not a video at all\n";
  EXPECT_NE(error_message([&] { VideoDecoder v(text); }).find(text), std::string::npos);
  const std::string message = error_message([&] { VideoDecoder v(text, -1); });
  EXPECT_NE(message.find("-1"), std::string::npos) << message;
}

TEST_F(VideoDecoderErrorTest, AskedThreadsAreUsed) {
  const std::string file = path("clip.mp4");
  {
    cv::VideoWriter writer(file, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), 25,
                           kDecoderSize);
    for (int k = 0; k < 4; ++k)
      writer.write(decoder_frame(k));
  }
  VideoDecoder video(file, 2);
  EXPECT_EQ(video.threads(), 2);
  DecodedFrame f;
  std::string failure;
  int n = 0;
  while (video.read(f, failure))
    ++n;
  EXPECT_EQ(n, 4) << failure;
}

}  // namespace
}  // namespace roiflow::video
