#include "eval/traffic_scene.hpp"

#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "eval/mot.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
using eval::MotBox;
using eval::TrafficScene;
using eval::TrafficSceneParams;

TrafficSceneParams params(long long frames, int objects, cv::Size size = {640, 480}) {
  TrafficSceneParams p;
  p.frames = frames;
  p.objects = objects;
  p.size = size;
  return p;
}

TEST(TrafficScene, SixteenVehiclesCrossEnterLeaveAndChangeSpeed) {
  const TrafficScene scene(params(300, 16));
  const std::vector<MotBox> gt = scene.ground_truth();
  std::map<int, std::vector<MotBox>> tracks;
  for (const MotBox& b : gt)
    tracks[b.id].push_back(b);

  // Most of the 16 are inside at frame 0; all 16 show up in 300 frames.
  const std::vector<MotBox> first = scene.boxes(0);
  EXPECT_GE(first.size(), 10u);
  std::set<int> vehicles;
  for (const auto& [id, boxes] : tracks)
    vehicles.insert((id - 1) % 16);
  EXPECT_EQ(vehicles.size(), 16u);

  int entered = 0, left = 0, speed_changes = 0;
  for (const auto& [id, boxes] : tracks) {
    // One pass is one run of consecutive frames.
    for (std::size_t k = 1; k < boxes.size(); ++k)
      ASSERT_EQ(boxes[k].frame, boxes[k - 1].frame + 1) << "id " << id;
    if (boxes.front().frame > 1) ++entered;
    if (boxes.back().frame < 300) ++left;
    // Frame-to-frame motion of a fully visible vehicle: the lane speed swings.
    double slowest = 1e9, fastest = 0;
    for (std::size_t k = 1; k < boxes.size(); ++k) {
      const cv::Rect2d& a = boxes[k - 1].box;
      const cv::Rect2d& b = boxes[k].box;
      if (a.size() != b.size()) continue;  // clipped at a border
      const double step = std::hypot(b.x - a.x, b.y - a.y);
      slowest = std::min(slowest, step);
      fastest = std::max(fastest, step);
    }
    if (fastest > 2 * slowest && slowest > 0) ++speed_changes;
  }
  EXPECT_GE(entered, 4);
  EXPECT_GE(left, 4);
  EXPECT_GE(speed_changes, 8);

  // Crossings: boxes of different vehicles overlap in some frames.
  int overlapping_frames = 0;
  for (long long i = 0; i < scene.frames(); ++i) {
    const std::vector<MotBox> boxes = scene.boxes(i);
    bool any = false;
    for (std::size_t a = 0; a < boxes.size(); ++a)
      for (std::size_t b = a + 1; b < boxes.size(); ++b)
        any = any || eval::mot_iou(boxes[a].box, boxes[b].box) > 0.05;
    overlapping_frames += any;
  }
  EXPECT_GE(overlapping_frames, 30);
}

TEST(TrafficScene, BoxesAreTheExactExtentOfWhatIsDrawn) {
  TrafficSceneParams p = params(40, 6);
  p.noise = 0;
  const TrafficScene scene(p);
  const cv::Mat background = scene.background();
  int checked = 0;
  for (long long i = 0; i < scene.frames(); i += 7) {
    const cv::Mat frame = scene.render(i);
    cv::Mat diff;
    cv::absdiff(frame, background, diff);
    cv::Mat changed;
    cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
    changed = changed > 0;
    cv::Mat covered(frame.size(), CV_8U, cv::Scalar(0));
    for (MotBox b : scene.boxes(i)) {
      b.box.x -= 1;  // MOTChallenge coordinates are 1-based
      b.box.y -= 1;
      // Pixels that a box touches (rounded outwards) may change; the rest may not.
      const cv::Rect r(
          cv::Point(static_cast<int>(std::floor(b.box.x)), static_cast<int>(std::floor(b.box.y))),
          cv::Point(static_cast<int>(std::ceil(b.box.x + b.box.width)),
                    static_cast<int>(std::ceil(b.box.y + b.box.height))));
      covered(r & cv::Rect(cv::Point(), frame.size())).setTo(255);
      // The box's middle row is drawn from end to end (the rounded corners spare it).
      const int y = static_cast<int>(b.box.y + b.box.height / 2);
      const int x0 = static_cast<int>(std::ceil(b.box.x)) + 1;
      const int x1 = static_cast<int>(std::floor(b.box.x + b.box.width)) - 2;
      if (x0 >= 0 && x1 < frame.cols && b.box.width > 20) {
        EXPECT_GT(cv::countNonZero(changed.row(y).colRange(x0, x1 + 1)), (x1 - x0 + 1) * 0.8);
        ++checked;
      }
    }
    cv::Mat outside;
    cv::bitwise_and(changed, ~covered, outside);
    EXPECT_EQ(cv::countNonZero(outside), 0) << "frame " << i;
  }
  EXPECT_GT(checked, 5);
}

TEST(TrafficScene, DeterministicAndSeeded) {
  const TrafficScene a(params(10, 8)), b(params(10, 8));
  EXPECT_EQ(cv::norm(a.render(5), b.render(5), cv::NORM_INF), 0);
  TrafficSceneParams other = params(10, 8);
  other.seed = 2;
  EXPECT_GT(cv::norm(a.render(5), TrafficScene(other).render(5), cv::NORM_L1), 0);
  EXPECT_EQ(eval::format_mot(a.ground_truth()), eval::format_mot(b.ground_truth()));
}

TEST(TrafficScene, LongRunsBringVehiclesBackWithNewIds) {
  const TrafficScene scene(params(2000, 1));
  std::set<int> ids;
  for (const MotBox& b : scene.ground_truth())
    ids.insert(b.id);
  EXPECT_GE(ids.size(), 3u);  // the one vehicle passes again and again, a new id each time
  EXPECT_EQ(*ids.begin(), 1);
  // Far into a long stream frames still render and hold traffic.
  TrafficScene soak(params(1'000'000'000, 16));
  EXPECT_EQ(soak.render(999'999'999).size(), cv::Size(640, 480));
  EXPECT_FALSE(soak.boxes(999'999'999).empty());
}

TEST(TrafficScene, SmallAndWideFramesKeepVehiclesInside) {
  for (const cv::Size size : {cv::Size(64, 64), cv::Size(1920, 1080), cv::Size(200, 600)}) {
    const TrafficScene scene(params(60, 64, size));
    for (long long i = 0; i < 60; i += 10) {
      EXPECT_EQ(scene.render(i).size(), size);
      for (const MotBox& b : scene.boxes(i)) {
        EXPECT_GE(b.box.x, 1);  // 1-based
        EXPECT_GE(b.box.y, 1);
        EXPECT_LE(b.box.x - 1 + b.box.width, size.width + 1e-9);
        EXPECT_LE(b.box.y - 1 + b.box.height, size.height + 1e-9);
        EXPECT_GE(b.box.width, 8);
        EXPECT_GE(b.box.height, 8);
      }
    }
  }
}

TEST(TrafficScene, RejectsBadParams) {
  const auto fails = [](TrafficSceneParams p, const std::string& expected) {
    const std::string message = test::error_message([&] { TrafficScene scene(p); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  fails(params(0, 4), "frames");
  fails(params(10, 0), "objects");
  fails(params(10, 257), "objects");
  fails(params(10, 4, {32, 480}), "size");
  TrafficSceneParams noisy = params(10, 4);
  noisy.noise = -1;
  fails(noisy, "noise");
  const TrafficScene scene(params(10, 4));
  EXPECT_NE(test::error_message([&] { scene.render(10); }).find("outside 0..9"), std::string::npos);
  EXPECT_NE(test::error_message([&] { scene.boxes(-1); }).find("outside"), std::string::npos);
}

}  // namespace
