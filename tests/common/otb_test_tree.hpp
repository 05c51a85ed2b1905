// Synthetic OTB-layout sequences for the benchmark tests (pipeline, CLI): frames of
// eval::TrackingScene written as img/0001.png ... and its exact boxes as groundtruth_rect.txt.
//
//   roiflow::test::OtbSequenceSpec spec;            // 20 frames, OTB's x,y,w,h
//   spec.tiny_tlp = true;                           // or TinyTLP's 6 columns
//   spec.absent = {5, 6};                           // frames 5 and 6: target absent
//   roiflow::test::write_otb_sequence(dir_ / "bench" / "tlp", spec);
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "eval/tracking_scene.hpp"

namespace roiflow::test {

struct OtbSequenceSpec {
  int frames = 20;
  std::uint64_t seed = 1;
  bool tiny_tlp = false;  // 6 columns frame,x,y,w,h,absent instead of x,y,w,h
  std::set<int> absent;   // 1-based frames marked absent (NaN line, or absent = 1)
  char separator = ',';   // between an OTB line's values
  bool gray = false;      // 1-channel frames
};

// Writes the sequence under `dir` and returns its exact boxes (absent ones included as drawn).
inline std::vector<cv::Rect2f> write_otb_sequence(const std::filesystem::path& dir,
                                                  const OtbSequenceSpec& spec) {
  eval::TrackingSceneParams params;
  params.size = {160, 120};
  params.frames = std::max(spec.frames, 3);
  params.seed = spec.seed;
  params.object = {36.f, 24.f};
  params.jump = 0;  // a smooth path: every tracker has a fair chance
  params.noise = 1.0;
  const eval::TrackingScene scene(params);
  std::filesystem::create_directories(dir / "img");
  std::ofstream truth(dir / "groundtruth_rect.txt");
  truth.precision(9);  // the boxes as drawn, to float precision
  std::vector<cv::Rect2f> boxes;
  for (int i = 0; i < spec.frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%04d.png", i + 1);
    cv::Mat frame = scene.render(i);
    if (spec.gray) cv::cvtColor(frame, frame, cv::COLOR_BGR2GRAY);
    EXPECT_TRUE(cv::imwrite((dir / "img" / name).string(), frame));
    const cv::Rect2f b = scene.box(i);
    boxes.push_back(b);
    const bool absent = spec.absent.count(i + 1) > 0;
    const char s = spec.separator;
    if (spec.tiny_tlp) {
      truth << i + 1 << ',' << b.x << ',' << b.y << ',' << b.width << ',' << b.height << ','
            << (absent ? 1 : 0) << '\n';
    } else if (absent) {
      truth << "NaN" << s << "NaN" << s << "NaN" << s << "NaN\n";
    } else {
      truth << b.x << s << b.y << s << b.width << s << b.height << '\n';
    }
  }
  return boxes;
}

}  // namespace roiflow::test
