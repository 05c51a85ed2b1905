// The CLI tests' input video: the demo's fixed-camera scene, small and short.
//
//   scene_ = test::write_scene_video(path("scene.avi"), 30);   // then scene_->box(i)
//   run({"track", path("scene.avi"), "--init", test::box_text(scene_->box(0))});
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <opencv2/videoio.hpp>
#include <string>

#include "eval/tracking_scene.hpp"

namespace roiflow::test {

// 160x120, a 28x18 object with a 10 px jump, `frames` frames as MJPG .avi at 25 fps.
inline std::unique_ptr<eval::TrackingScene> write_scene_video(const std::string& path, int frames) {
  eval::TrackingSceneParams params;
  params.size = {160, 120};
  params.frames = frames;
  params.object = {28.f, 18.f};
  params.jump = 10.0;
  auto scene = std::make_unique<eval::TrackingScene>(params);
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0,
                         params.size);
  EXPECT_TRUE(writer.isOpened()) << path;
  for (int i = 0; i < scene->frames(); ++i)
    writer.write(scene->render(i));
  return scene;
}

// "x,y,w,h", as --init takes it.
inline std::string box_text(const cv::Rect2f& b) {
  return std::to_string(b.x) + "," + std::to_string(b.y) + "," + std::to_string(b.width) + "," +
         std::to_string(b.height);
}

}  // namespace roiflow::test
