#include "eval/otb_score.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using eval::center_error;
using eval::iou;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A target drifting right and down, the size of a small OTB car.
std::vector<cv::Rect2f> moving_box(int frames, cv::Size2f size = {40, 40}) {
  std::vector<cv::Rect2f> boxes;
  for (int i = 0; i < frames; ++i)
    boxes.emplace_back(100.f + 3.f * i, 50.f + 1.5f * i, size.width, size.height);
  return boxes;
}

std::vector<cv::Rect2f> shifted_boxes(std::vector<cv::Rect2f> boxes, cv::Point2f by) {
  for (cv::Rect2f& box : boxes) {
    box.x += by.x;
    box.y += by.y;
  }
  return boxes;
}

class OtbScoreTest : public test::TempDirTest {};

TEST_F(OtbScoreTest, GroundTruthMixesCommasTabsAndSpaces) {
  test::write_text(path("gt.txt"),
                   "70,51,107,87\r\n"
                   "71\t52\t106\t86\n"
                   "  \t \n"
                   "72 53 105 85\n"
                   "\r\n"
                   "73, 54,104  84\n"
                   "0,0,0,0\n"
                   "NaN,NaN,NaN,NaN\n"
                   "1.5\t,2.25 , 3e1,4");  // no final line end
  const std::vector<cv::Rect2f> boxes = eval::read_ground_truth(path("gt.txt"));
  ASSERT_EQ(boxes.size(), 7u);
  EXPECT_EQ(boxes[0], cv::Rect2f(70, 51, 107, 87));
  EXPECT_EQ(boxes[1], cv::Rect2f(71, 52, 106, 86));
  EXPECT_EQ(boxes[2], cv::Rect2f(72, 53, 105, 85));
  EXPECT_EQ(boxes[3], cv::Rect2f(73, 54, 104, 84));
  EXPECT_EQ(boxes[4], cv::Rect2f(0, 0, 0, 0));
  EXPECT_TRUE(std::isnan(boxes[5].x) && std::isnan(boxes[5].height));
  EXPECT_EQ(boxes[6], cv::Rect2f(1.5f, 2.25f, 30, 4));
}

TEST_F(OtbScoreTest, GroundTruthErrorsNameFileLineAndValue) {
  struct Case {
    std::string text;
    std::string expected;  // besides the path
  };
  const std::vector<Case> cases = {
      {"1,2,3,4\n1,2,3\n", ":2: expected 4 values x,y,w,h, got 3"},
      {"\n1,2,3,4,5,6,7,8\n", ":2: expected 4 values x,y,w,h, got 8"},
      {"1,,2,3\n", ":1: empty value 2"},
      {",1,2,3\n", ":1: empty value 1"},
      {"1,2,3,4,\n", ":1: empty value after the last comma"},
      {"1,2,3,4\n1,2,3,4\n1;2;3;4\n", ":3: expected 4 values"},
      {"a,2,3,4\n", ":1: value 1 'a' is not a finite number"},
      {"1,2,3,4px\n", ":1: value 4 '4px' is not a finite number"},
      {"1,2,inf,4\n", ":1: value 3 'inf'"},
      {"1,NaN,3,4\n", ":1: partly NaN box"},
      {"1,2,-3,4\n", ":1: negative size -3x4"},
      {"", "holds no box"},
      {"\n \r\n", "holds no box"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    test::write_text(path("gt.txt"), c.text);
    const std::string message =
        test::error_message([&] { eval::read_ground_truth(path("gt.txt")); });
    EXPECT_NE(message.find(path("gt.txt")), std::string::npos) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
  const std::string missing = path("missing.txt");
  EXPECT_NE(test::error_message([&] { eval::read_ground_truth(missing); }).find(missing),
            std::string::npos);
}

TEST_F(OtbScoreTest, IouHandComputed) {
  const cv::Rect2f a(0, 0, 10, 10);
  EXPECT_DOUBLE_EQ(iou(a, a), 1.0);
  EXPECT_DOUBLE_EQ(iou(a, {5, 0, 10, 10}), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(iou({5, 0, 10, 10}, a), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(iou(a, {5, 5, 10, 10}), 25.0 / 175.0);
  EXPECT_DOUBLE_EQ(iou(a, {2, 2, 4, 4}), 16.0 / 100.0);
  EXPECT_DOUBLE_EQ(iou(a, {-5, 2.5f, 20, 5}), 50.0 / (100.0 + 100.0 - 50.0));
  EXPECT_DOUBLE_EQ(iou(a, {10, 0, 10, 10}), 0.0);  // touching edges
  EXPECT_DOUBLE_EQ(iou(a, {30, 30, 10, 10}), 0.0);
  EXPECT_DOUBLE_EQ(iou(a, {0, 0, 0, 10}), 0.0);  // empty
  EXPECT_DOUBLE_EQ(iou({0, 0, 0, 0}, {0, 0, 0, 0}), 0.0);
  EXPECT_DOUBLE_EQ(iou(a, {2, 2, -4, 4}), 0.0);
  EXPECT_DOUBLE_EQ(iou(a, {kNaN, 0, 10, 10}), 0.0);
}

TEST_F(OtbScoreTest, CenterErrorHandComputed) {
  const cv::Rect2f a(0, 0, 10, 10);
  EXPECT_DOUBLE_EQ(center_error(a, a), 0.0);
  EXPECT_DOUBLE_EQ(center_error(a, {3, 4, 10, 10}), 5.0);
  EXPECT_DOUBLE_EQ(center_error({3, 4, 10, 10}, a), 5.0);
  // Centres (5, 5) and (10, 15).
  EXPECT_DOUBLE_EQ(center_error(a, {0, 0, 20, 30}), std::sqrt(125.0));
  EXPECT_DOUBLE_EQ(center_error(a, {5, 5, 0, 0}), 0.0);  // an empty box still has a centre
  EXPECT_TRUE(std::isinf(center_error(a, {0, kNaN, 10, 10})));
}

// OTB counts IoU > threshold, so the threshold 1 is never passed: 20 of 21 thresholds.
TEST_F(OtbScoreTest, PerfectTrackScores20Of21) {
  const std::vector<cv::Rect2f> truth = moving_box(50);
  const eval::OtbScore s = eval::score(truth, truth);
  EXPECT_DOUBLE_EQ(s.auc, 20.0 / 21.0);
  EXPECT_DOUBLE_EQ(s.precision20, 1.0);
  EXPECT_DOUBLE_EQ(s.mean_iou, 1.0);
  EXPECT_EQ(s.frames, 50);
}

TEST_F(OtbScoreTest, TrackShiftedBy10Pixels) {
  const std::vector<cv::Rect2f> truth = moving_box(30);
  // 40x40 boxes 10 px apart: overlap 30x40 = 1200, union 3200 - 1200 = 2000, IoU 0.6, which
  // passes the 12 thresholds 0 .. 0.55.
  const eval::OtbScore s = eval::score(shifted_boxes(truth, {10, 0}), truth);
  EXPECT_DOUBLE_EQ(s.mean_iou, 0.6);
  EXPECT_DOUBLE_EQ(s.auc, 12.0 / 21.0);
  EXPECT_DOUBLE_EQ(s.precision20, 1.0);
  EXPECT_EQ(s.frames, 30);
}

TEST_F(OtbScoreTest, ThresholdsAreStrictForIouAndInclusiveForDistance) {
  const std::vector<cv::Rect2f> truth = moving_box(10, {30, 30});
  // 30x30 boxes 10 px apart: overlap 600, union 1200, IoU exactly 0.5, not above 0.5.
  const eval::OtbScore half = eval::score(shifted_boxes(truth, {0, 10}), truth);
  EXPECT_DOUBLE_EQ(half.mean_iou, 0.5);
  EXPECT_DOUBLE_EQ(half.auc, 10.0 / 21.0);
  // A 12-16-20 triangle: exactly 20 px counts as precise; a hair more does not.
  EXPECT_DOUBLE_EQ(eval::score(shifted_boxes(truth, {12, 16}), truth).precision20, 1.0);
  EXPECT_DOUBLE_EQ(eval::score(shifted_boxes(truth, {12, 16.25f}), truth).precision20, 0.0);
}

TEST_F(OtbScoreTest, AbsentTargetFramesAreSkipped) {
  std::vector<cv::Rect2f> truth = moving_box(6);
  std::vector<cv::Rect2f> track = truth;
  truth[1] = {0, 0, 0, 0};
  truth[2] = {kNaN, kNaN, kNaN, kNaN};
  truth[3] = {5, 5, 0, 7};
  track[1] = track[2] = track[3] = {900, 900, 5, 5};  // whatever the tracker says there
  track[5] = {0, 0, 1, 1};                            // a real miss: IoU 0, far away
  const eval::OtbScore s = eval::score(track, truth);
  EXPECT_EQ(s.frames, 3);
  EXPECT_DOUBLE_EQ(s.mean_iou, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.precision20, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.auc, 2.0 / 3.0 * 20.0 / 21.0);
}

TEST_F(OtbScoreTest, ScoresTheFramesBothHave) {
  const std::vector<cv::Rect2f> truth = moving_box(20);
  std::vector<cv::Rect2f> short_track(truth.begin(), truth.begin() + 7);
  EXPECT_EQ(eval::score(short_track, truth).frames, 7);
  std::vector<cv::Rect2f> long_track = truth;
  long_track.resize(25, cv::Rect2f(0, 0, 1, 1));
  const eval::OtbScore s = eval::score(long_track, truth);
  EXPECT_EQ(s.frames, 20);
  EXPECT_DOUBLE_EQ(s.mean_iou, 1.0);
}

TEST_F(OtbScoreTest, NothingToScoreThrows) {
  const std::string empty = test::error_message([] { eval::score({}, moving_box(5)); });
  EXPECT_NE(empty.find("the track has 0 boxes, the ground truth 5"), std::string::npos) << empty;
  const std::vector<cv::Rect2f> absent(4, cv::Rect2f(0, 0, 0, 0));
  const std::string all_absent = test::error_message([&] { eval::score(moving_box(3), absent); });
  EXPECT_NE(all_absent.find("absent in all 3"), std::string::npos) << all_absent;
}

TEST_F(OtbScoreTest, TrackBoxesNeedFramesOneTwoThree) {
  std::vector<eval::TrackRecord> records(3);
  for (int i = 0; i < 3; ++i) {
    records[i].frame = i + 1;
    records[i].box = {static_cast<float>(i), 0, 4, 4};
  }
  const std::vector<cv::Rect2f> boxes = eval::track_boxes(records);
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_EQ(boxes[2], cv::Rect2f(2, 0, 4, 4));

  records[2].frame = 5;
  const std::string gap = test::error_message([&] { eval::track_boxes(records); });
  EXPECT_NE(gap.find("record 3 is frame 5, expected frame 3"), std::string::npos) << gap;
  records[0].frame = 0;
  EXPECT_NE(test::error_message([&] { eval::track_boxes(records); }).find("record 1 is frame 0"),
            std::string::npos);
}

TEST_F(OtbScoreTest, ParseGroundTruthReadsTextAndNamesItInErrors) {
  const std::vector<cv::Rect2f> boxes = eval::parse_ground_truth("1,2,3,4\r\n\n5 6 7 8", "mem");
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[1], cv::Rect2f(5, 6, 7, 8));
  EXPECT_NE(test::error_message([] {
              eval::parse_ground_truth("1,2,3\n", "mem.txt");
            }).find("mem.txt:1: expected 4 values"),
            std::string::npos);
  EXPECT_NE(test::error_message([] {
              eval::parse_ground_truth(" \n\t\n", "blank");
            }).find("holds no box"),
            std::string::npos);
}

// Found by fuzzing (tests/fuzz_regressions/ground_truth): a double beyond the float range became
// an infinite box.
TEST_F(OtbScoreTest, GroundTruthValuesBeyondTheFloatRangeAreRejected) {
  const std::string message =
      test::error_message([] { eval::parse_ground_truth("1,2,1e39,4\n", "big.txt"); });
  EXPECT_NE(message.find("big.txt:1: value 3 '1e39' is too large"), std::string::npos) << message;
  EXPECT_EQ(eval::parse_ground_truth("3e38,0,1,1", "ok")[0].x, 3e38f);
}

// Found by fuzzing: far from the origin the box's right edge rounded up (x = 7e17, a double's
// step there is 128) and the IoU of a box with itself came out as 1.49.
TEST_F(OtbScoreTest, IouStaysExactFarFromTheOrigin) {
  for (const float x : {7e17f, -7e17f, 1e30f, 3e38f}) {
    const cv::Rect2f box(x, 51, 107, 87);
    EXPECT_DOUBLE_EQ(iou(box, box), 1.0) << x;
    EXPECT_DOUBLE_EQ(iou(box, cv::Rect2f(x, 51, 107, 43.5f)), 0.5) << x;
  }
  const std::vector<cv::Rect2f> far = {{7e17f, 51, 107, 87}, {42, 51, 107, 87}};
  EXPECT_NEAR(eval::score(far, far).auc, 20.0 / 21.0, 1e-12);
  EXPECT_DOUBLE_EQ(eval::score(far, far).mean_iou, 1.0);
}

}  // namespace
