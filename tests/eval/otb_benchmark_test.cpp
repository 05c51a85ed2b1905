// OTB benchmark scoring: TinyTLP ground truth, the success and precision curves, the lost share,
// per-tracker means and the tables, each against figures computed by hand.
#include "eval/otb_benchmark.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "eval/otb_score.hpp"
#include "test_util.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;
using test::error_message;
using test::lines_of;

const float kNan = std::numeric_limits<float>::quiet_NaN();

// The hand case: four 10x10 truth boxes at the origin, the third absent.
//   frame 1: exact                  IoU 1,                 centre error 0
//   frame 2: 5 px to the right      IoU 50 / 150 = 1/3,    centre error 5
//   frame 3: target absent          not scored
//   frame 4: 30 px to the right     IoU 0,                 centre error 30
// success[k] (IoU > k / 20): 2/3 for k = 0..6 (6/20 = 0.30 < 1/3 < 0.35), 1/3 for k = 7..19
// (only IoU 1), 0 for k = 20 (IoU 1 is not > 1). AUC = (7 * 2/3 + 13 * 1/3) / 21 = 9 / 21.
// precision[t] (error <= t): 1/3 for t = 0..4, 2/3 for t = 5..29, 1 from t = 30.
// Mean IoU (1 + 1/3 + 0) / 3 = 4/9.
std::vector<cv::Rect2f> hand_truth() {
  return {{0, 0, 10, 10}, {0, 0, 10, 10}, {kNan, kNan, kNan, kNan}, {0, 0, 10, 10}};
}
std::vector<cv::Rect2f> hand_track() {
  return {{0, 0, 10, 10}, {5, 0, 10, 10}, {0, 0, 10, 10}, {30, 0, 10, 10}};
}

TEST(OtbBenchmarkTest, CurvesMatchTheHandCase) {
  const OtbCurves c = otb_curves(hand_track(), hand_truth());
  EXPECT_EQ(c.frames, 3);
  ASSERT_EQ(c.success.size(), 21u);
  ASSERT_EQ(c.precision.size(), 51u);
  for (int k = 0; k <= 20; ++k) {
    const double expected = k <= 6 ? 2.0 / 3 : k <= 19 ? 1.0 / 3 : 0.0;
    EXPECT_DOUBLE_EQ(c.success[k], expected) << "k = " << k;
  }
  for (int t = 0; t <= 50; ++t) {
    const double expected = t <= 4 ? 1.0 / 3 : t <= 29 ? 2.0 / 3 : 1.0;
    EXPECT_DOUBLE_EQ(c.precision[t], expected) << "t = " << t;
  }
  EXPECT_NEAR(curve_auc(c.success), 9.0 / 21, 1e-12);
  // score() agrees with the curves.
  const OtbScore s = score(hand_track(), hand_truth());
  EXPECT_NEAR(s.auc, 9.0 / 21, 1e-12);
  EXPECT_DOUBLE_EQ(s.precision20, 2.0 / 3);
  EXPECT_NEAR(s.mean_iou, 4.0 / 9, 1e-12);
}

TEST(OtbBenchmarkTest, ScoreRunCountsTheLostFramesAmongTheMisses) {
  TrackerRun run;
  run.boxes = hand_track();
  run.lost = {false, true, true, true};  // frame 3 is absent: its flag counts as lost only
  run.cpu_s = 0.5;
  const BenchmarkRow r = score_run("seq", "t", hand_truth(), run);
  EXPECT_EQ(r.frames, 4);
  EXPECT_EQ(r.scored, 3);
  EXPECT_NEAR(r.auc, 9.0 / 21, 1e-12);
  EXPECT_DOUBLE_EQ(r.precision20, 2.0 / 3);
  EXPECT_NEAR(r.mean_iou, 4.0 / 9, 1e-12);
  EXPECT_DOUBLE_EQ(r.fps, 8.0);
  EXPECT_EQ(r.lost, 3);
  EXPECT_EQ(r.zero_iou, 1);
  EXPECT_EQ(r.zero_iou_lost, 1);
  EXPECT_DOUBLE_EQ(r.lost_share(), 1.0);

  run.lost = {true, true, false, false};  // lost where it is right, found where it is wrong
  const BenchmarkRow wrong = score_run("seq", "t", hand_truth(), run);
  EXPECT_EQ(wrong.zero_iou_lost, 0);
  EXPECT_DOUBLE_EQ(wrong.lost_share(), 0.0);

  TrackerRun perfect;
  perfect.boxes = {{0, 0, 10, 10}};
  perfect.lost = {false};
  const BenchmarkRow p = score_run("seq", "t", hand_truth(), perfect);
  EXPECT_EQ(p.zero_iou, 0);
  EXPECT_TRUE(std::isnan(p.lost_share()));
  EXPECT_TRUE(std::isinf(p.fps));  // no time measured

  run.lost.pop_back();
  EXPECT_NE(error_message([&] {
              score_run("seq", "t", hand_truth(), run);
            }).find("4 boxes but 3 lost flags"),
            std::string::npos);
}

TEST(OtbBenchmarkTest, MeansAverageScoresPerSequenceAndPoolFramesAndTime) {
  TrackerRun a;  // the hand case: AUC 9/21, 4 frames in 0.5 s, 1 miss reported lost
  a.boxes = hand_track();
  a.lost = {false, false, false, true};
  a.cpu_s = 0.5;
  TrackerRun b;  // perfect on 2 frames: AUC 20/21, 2 frames in 1.5 s
  b.boxes = {{0, 0, 10, 10}, {0, 0, 10, 10}};
  b.lost = {false, false};
  b.cpu_s = 1.5;
  TrackerRun c;  // all wrong on 2 frames, never reported lost
  c.boxes = {{50, 50, 10, 10}, {50, 50, 10, 10}};
  c.lost = {false, false};
  c.cpu_s = 0.25;
  const std::vector<cv::Rect2f> truth2 = {{0, 0, 10, 10}, {0, 0, 10, 10}};
  const std::vector<BenchmarkRow> rows = {
      score_run("s1", "x", hand_truth(), a), score_run("s1", "y", hand_truth(), a),
      score_run("s2", "x", truth2, b), score_run("s2", "y", truth2, c)};
  const std::vector<BenchmarkRow> means = tracker_means(rows, {"x", "y"});
  ASSERT_EQ(means.size(), 2u);
  const BenchmarkRow& x = means[0];
  EXPECT_EQ(x.sequence, "mean");
  EXPECT_EQ(x.tracker, "x");
  EXPECT_EQ(x.sequences, 2);
  EXPECT_EQ(x.frames, 6);
  EXPECT_NEAR(x.auc, (9.0 / 21 + 20.0 / 21) / 2, 1e-12);
  EXPECT_NEAR(x.precision20, (2.0 / 3 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(x.mean_iou, (4.0 / 9 + 1.0) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(x.fps, 6 / 2.0);  // 6 frames in 0.5 + 1.5 s
  EXPECT_NEAR(x.curves.success[10], (1.0 / 3 + 1.0) / 2, 1e-12);
  EXPECT_NEAR(curve_auc(x.curves.success), x.auc, 1e-12);
  EXPECT_EQ(x.zero_iou, 1);
  EXPECT_EQ(x.zero_iou_lost, 1);
  const BenchmarkRow& y = means[1];
  EXPECT_NEAR(y.auc, (9.0 / 21 + 0.0) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(y.fps, 6 / 0.75);
  EXPECT_EQ(y.zero_iou, 3);  // 1 in s1, 2 in s2
  EXPECT_EQ(y.zero_iou_lost, 1);
  EXPECT_NEAR(y.lost_share(), 1.0 / 3, 1e-12);

  EXPECT_NE(error_message([&] {
              tracker_means(rows, {"x", "z"});
            }).find("'z' has no"),
            std::string::npos);
  std::vector<BenchmarkRow> uneven = rows;
  uneven.pop_back();
  EXPECT_NE(error_message([&] {
              tracker_means(uneven, {"x", "y"});
            }).find("other sequences"),
            std::string::npos);
}

TEST(OtbBenchmarkTest, TablesHoldEveryRowAndTheMeans) {
  TrackerRun a;
  a.boxes = hand_track();
  a.lost = {false, false, false, true};
  a.cpu_s = 0.5;
  TrackerRun never;
  never.boxes = {{0, 0, 10, 10}};
  never.lost = {false};
  never.cpu_s = 0.25;
  const std::vector<BenchmarkRow> rows = {score_run("s1", "x", hand_truth(), a),
                                          score_run("s1", "y", hand_truth(), never)};
  const std::vector<BenchmarkRow> means = tracker_means(rows, {"x", "y"});
  const std::vector<std::string> csv = lines_of(format_benchmark_csv(rows, means));
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[0],
            "sequence,tracker,frames,scored,auc,precision20,mean_iou,fps,cpu_s,lost,zero_iou,"
            "zero_iou_lost,lost_share");
  EXPECT_EQ(csv[1], "s1,x,4,3,0.4286,0.6667,0.4444,8.00,0.5000,1,1,1,1.0000");
  EXPECT_EQ(csv[2], "s1,y,1,1,0.9524,1.0000,1.0000,4.00,0.2500,0,0,0,");  // no miss: no share
  EXPECT_EQ(csv[3], "mean,x,4,3,0.4286,0.6667,0.4444,8.00,0.5000,1,1,1,1.0000");
  EXPECT_EQ(csv[4].rfind("mean,y,", 0), 0u);

  const std::string md = format_benchmark_markdown(rows, means);
  EXPECT_NE(md.find("| sequence | x | y |"), std::string::npos) << md;
  EXPECT_NE(md.find("| s1 | 0.429 | 0.952 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| **mean** | **0.429** | **0.952** |"), std::string::npos) << md;
  EXPECT_NE(md.find("| s1 | x | 4 | 0.429 | 0.667 | 0.444 | 8.0 | 1 | 1.00 (1/1) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| s1 | y | 1 | 0.952 | 1.000 | 1.000 | 4.0 | 0 | - (0 frames) |"),
            std::string::npos)
      << md;
}

TEST(OtbBenchmarkTest, TablesEscapeNamesThatWouldBreakThem) {
  TrackerRun a;
  a.boxes = {{0, 0, 10, 10}};
  a.lost = {false};
  a.cpu_s = 1;
  const std::vector<BenchmarkRow> rows = {score_run("a,b \"c\"", "x", hand_truth(), a),
                                          score_run("d|e", "x", hand_truth(), a)};
  const std::vector<BenchmarkRow> means = tracker_means(rows, {"x"});
  const std::vector<std::string> csv = lines_of(format_benchmark_csv(rows, means));
  EXPECT_EQ(csv[1].rfind("\"a,b \"\"c\"\"\",x,1,", 0), 0u) << csv[1];
  const std::string md = format_benchmark_markdown(rows, means);
  EXPECT_NE(md.find("| d\\|e | 0.952 |"), std::string::npos) << md;
}

TEST(OtbBenchmarkTest, TinyTlpGroundTruthHasSixColumnsAndAnAbsentFlag) {
  const std::vector<cv::Rect2f> boxes =
      parse_ground_truth("1,495,343,172,109,0\n2,496,344,170,108,1\n3 497 345 171 110 0\n", "tlp");
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_EQ(boxes[0], cv::Rect2f(495, 343, 172, 109));
  EXPECT_TRUE(std::isnan(boxes[1].x) && std::isnan(boxes[1].width));
  EXPECT_EQ(boxes[2], cv::Rect2f(497, 345, 171, 110));
  const struct {
    const char* text;
    const char* expected;
  } bad[] = {
      {"1,1,2,3,4,0\n3,1,2,3,4,0\n", "tlp:2: TinyTLP frame number 3, expected 2"},
      {"1,1,2,3,4,0\n2,1,2,3,4\n", "tlp:2: expected 6 values frame,x,y,w,h,absent"},
      {"1,1,2,3,4,2\n", "tlp:1: TinyTLP absent flag 2 is neither 0 nor 1"},
      {"1.5,1,2,3,4,0\n", "tlp:1: value 1 '1.5' is not an integer"},
      {"1,1,2,-3,4,0\n", "tlp:1: negative size"},
      {"1,2,3,4\n1,1,2,3,4,0\n", "tlp:2: expected 4 values x,y,w,h, got 6"},
      {"1,2,3,4,5\n", "tlp:1: expected 4 values x,y,w,h, got 5 (TinyTLP files have 6"},
  };
  for (const auto& b : bad) {
    const std::string message = error_message([&] { parse_ground_truth(b.text, "tlp"); });
    EXPECT_NE(message.find(b.expected), std::string::npos) << b.text << " -> " << message;
  }
}

class OtbSequencesTest : public test::TempDirTest {
 protected:
  void sequence(const std::string& name, const std::string& truth) const {
    fs::create_directories(path(name + "/img"));
    std::ofstream(path(name + "/groundtruth_rect.txt")) << truth;
  }
};

TEST_F(OtbSequencesTest, FindsTheSequenceFoldersSortedAndSkipsTheRest) {
  sequence("root/b", "1,2,3,4\n1,2,3,4\n");
  sequence("root/a", "1\t2\t3\t4\nNaN,NaN,NaN,NaN\n");
  fs::create_directories(path("root/notes"));
  std::vector<std::string> skipped;
  const std::vector<OtbSequence> found = find_otb_sequences(path("root"), &skipped);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].name, "a");
  EXPECT_EQ(found[1].name, "b");
  EXPECT_EQ(found[0].dir, path("root/a"));
  EXPECT_EQ(found[0].truth.size(), 2u);
  EXPECT_TRUE(std::isnan(found[0].truth[1].x));
  EXPECT_EQ(skipped, std::vector<std::string>{"notes"});
  // A sequence's own folder is a benchmark of one.
  const std::vector<OtbSequence> one = find_otb_sequences(path("root/b") + "/");
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].name, "b");
}

TEST_F(OtbSequencesTest, BadFoldersAndGroundTruthFailNamingTheCause) {
  EXPECT_NE(error_message([&] { find_otb_sequences(path("missing")); }).find("not a directory"),
            std::string::npos);
  fs::create_directories(path("empty/x"));
  EXPECT_NE(error_message([&] { find_otb_sequences(path("empty")); }).find("holds no sequence"),
            std::string::npos);
  sequence("bad/s", "1,2,3\n");
  EXPECT_NE(error_message([&] {
              find_otb_sequences(path("bad"));
            }).find("s/groundtruth_rect.txt:1: expected 4 values"),
            std::string::npos);
  sequence("absent/s", "NaN,NaN,NaN,NaN\n1,2,3,4\n");
  EXPECT_NE(error_message([&] {
              find_otb_sequences(path("absent"));
            }).find("the target is absent in the first frame"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::eval
