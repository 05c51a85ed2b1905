// VideoSource on "synthetic:N[:WxH]:OBJECTS": the traffic scene, frame for frame.
#include <gtest/gtest.h>

#include <string>

#include "eval/synthetic_input.hpp"
#include "eval/traffic_scene.hpp"
#include "test_util.hpp"
#include "video/video_source.hpp"

namespace {

using namespace roiflow;
using roiflow::test::error_message;

TEST(SyntheticTrafficSource, DeliversTheTrafficSceneFrames) {
  video::VideoSource source("synthetic:12:320x240:5", {.fps = 25});
  EXPECT_EQ(source.size(), cv::Size(320, 240));
  EXPECT_EQ(source.frame_count_hint(), 12);
  EXPECT_NE(source.description().find("synthetic traffic (12 frames, 5 vehicles"),
            std::string::npos)
      << source.description();
  const eval::TrafficScene scene(
      eval::traffic_params(eval::parse_synthetic_input("synthetic:12:320x240:5")));
  long long count = 0;
  while (auto frame = source.next()) {
    EXPECT_EQ(cv::norm(frame->image, scene.render(frame->index), cv::NORM_INF), 0);
    ++count;
  }
  EXPECT_EQ(count, 12);
  EXPECT_EQ(source.status().state, video::SourceStatus::State::kEnded);
}

TEST(SyntheticTrafficSource, SpecGrammar) {
  const eval::SyntheticInput a = eval::parse_synthetic_input("synthetic:300:16");
  EXPECT_EQ(a.frames, 300);
  EXPECT_EQ(a.size, cv::Size(640, 480));
  EXPECT_EQ(a.objects, 16);
  const eval::SyntheticInput b = eval::parse_synthetic_input("synthetic:7:1280x720:64");
  EXPECT_EQ(b.size, cv::Size(1280, 720));
  EXPECT_EQ(b.objects, 64);
  const eval::SyntheticInput c = eval::parse_synthetic_input("synthetic:7:96x72");
  EXPECT_EQ(c.objects, 0);
  for (const char* input :
       {"synthetic:5:0", "synthetic:5:257", "synthetic:5:640x480:", "synthetic:5:640x480:16:1",
        "synthetic:5:16:640x480", "synthetic:5:640x480:x"}) {
    const std::string message = error_message([&] { video::VideoSource s(input); });
    EXPECT_NE(message.find(std::string("bad synthetic input '") + input + "'"), std::string::npos)
        << message;
  }
}

}  // namespace
