#include "eval/mot.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using eval::MotBox;
using eval::MotScore;

MotBox box(int frame, int id, double x, double y = 0, double w = 10, double h = 10) {
  MotBox b;
  b.frame = frame;
  b.id = id;
  b.box = {x, y, w, h};
  return b;
}

MotScore score_boxes(const std::vector<MotBox>& pred, const std::vector<MotBox>& gt) {
  return eval::score_mot(pred, gt);
}

TEST(MotScore, PerfectTrackWithOtherIdsScoresOne) {
  std::vector<MotBox> gt, pred;
  for (int f = 1; f <= 3; ++f) {
    gt.push_back(box(f, 1, 10.0 * f));
    gt.push_back(box(f, 2, 100, 50));
    pred.push_back(box(f, 7, 10.0 * f));
    pred.push_back(box(f, 3, 100, 50));
  }
  const MotScore s = score_boxes(pred, gt);
  EXPECT_DOUBLE_EQ(s.mota, 1.0);
  EXPECT_DOUBLE_EQ(s.motp, 1.0);
  EXPECT_DOUBLE_EQ(s.idf1, 1.0);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_EQ(s.frames, 3);
  EXPECT_EQ(s.objects, 2);
  EXPECT_EQ(s.matches, 6);
}

TEST(MotScore, IdSwitch) {
  // One object, frames 1-4; the tracker calls it 10, then 11.
  std::vector<MotBox> gt, pred;
  for (int f = 1; f <= 4; ++f) {
    gt.push_back(box(f, 1, 0));
    pred.push_back(box(f, f <= 2 ? 10 : 11, 0));
  }
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.id_switches, 1);
  EXPECT_EQ(s.fp, 0);
  EXPECT_EQ(s.fn, 0);
  EXPECT_DOUBLE_EQ(s.mota, 0.75);  // 1 - 1/4
  // Best id pairing: 1 <-> 10 (or 11), 2 frames. IDF1 = 2 * 2 / (4 + 4).
  EXPECT_DOUBLE_EQ(s.idf1, 0.5);
  EXPECT_EQ(s.tracks, 2);
}

TEST(MotScore, FalsePositiveAndMiss) {
  // Frame 1 matched at IoU 9/11; frame 2 the tracker box is elsewhere: 1 FN + 1 FP.
  const std::vector<MotBox> gt = {box(1, 1, 0), box(2, 1, 0)};
  const std::vector<MotBox> pred = {box(1, 5, 1), box(2, 5, 50)};
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.fn, 1);
  EXPECT_EQ(s.fp, 1);
  EXPECT_EQ(s.matches, 1);
  EXPECT_DOUBLE_EQ(s.mota, 0.0);  // 1 - 2/2
  EXPECT_NEAR(s.motp, 9.0 / 11.0, 1e-12);
  // Ids 1 and 5 overlap in 1 frame: IDF1 = 2 * 1 / (2 + 2).
  EXPECT_DOUBLE_EQ(s.idf1, 0.5);
}

TEST(MotScore, IouOfExactlyHalfMatchesAndBelowDoesNot) {
  // 10x10 inside a 20x10 box: IoU = 100 / 200.
  EXPECT_EQ(score_boxes({box(1, 1, 0, 0, 20, 10)}, {box(1, 1, 0)}).matches, 1);
  // 10x10 against 10x10 shifted by 4: IoU = 60 / 140 < 0.5.
  const MotScore s = score_boxes({box(1, 1, 4)}, {box(1, 1, 0)});
  EXPECT_EQ(s.matches, 0);
  EXPECT_EQ(s.fp, 1);
  EXPECT_EQ(s.fn, 1);
  EXPECT_DOUBLE_EQ(s.mota, -1.0);
}

TEST(MotScore, CrossingKeepsPreviousCorrespondenceWhileItHolds) {
  // Frame 1: A at 0, B at 20, tracker 1 on A, 2 on B. Frame 2 (crossing): A at 0, B at 2;
  // tracker 1 at 3, tracker 2 at 0. The least-cost matching alone would pair A-2 (IoU 1) and
  // B-1 (9/11): two switches. But A-1 (IoU 7/13) and B-2 (8/12) still hold, so they are kept.
  const std::vector<MotBox> gt = {box(1, 1, 0), box(1, 2, 20), box(2, 1, 0), box(2, 2, 2)};
  const std::vector<MotBox> pred = {box(1, 1, 0), box(1, 2, 20), box(2, 1, 3), box(2, 2, 0)};
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_EQ(s.matches, 4);
  EXPECT_NEAR(s.motp, (1 + 1 + 7.0 / 13.0 + 8.0 / 12.0) / 4, 1e-12);
}

TEST(MotScore, CrossingWithSwappedIdsCountsTwoSwitches) {
  // Two objects pass each other; after the crossing the tracker has their ids swapped.
  std::vector<MotBox> gt, pred;
  for (int f = 1; f <= 6; ++f) {
    const double a = 10.0 * f, b = 70 - 10.0 * f;
    gt.push_back(box(f, 1, a));
    gt.push_back(box(f, 2, b, 40));
    pred.push_back(box(f, f <= 3 ? 1 : 2, a));
    pred.push_back(box(f, f <= 3 ? 2 : 1, b, 40));
  }
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.id_switches, 2);
  EXPECT_DOUBLE_EQ(s.mota, 1.0 - 2.0 / 12.0);
  EXPECT_DOUBLE_EQ(s.idf1, 0.5);  // each id pairing covers 3 of 6 frames
}

TEST(MotScore, OptimalNotGreedyMatching) {
  // A at 0, B at 3; tracker p at 1 (IoU 9/11 with A, 8/12 with B), q at -3 (7/13 with A only).
  // Greedy by IoU takes A-p and leaves B unmatched; the optimum matches both.
  const MotScore s = score_boxes({box(1, 1, 1), box(1, 2, -3)}, {box(1, 1, 0), box(1, 2, 3)});
  EXPECT_EQ(s.matches, 2);
  EXPECT_EQ(s.fn, 0);
  EXPECT_EQ(s.fp, 0);
}

TEST(MotScore, IdF1PairsIdsGlobally) {
  // Tracker id 5 covers object 1 in frames 1-3, then object 2 in frames 4-6 (object 1 gone):
  // no CLEAR switch (object 2 never had another match), but one id can pair with one object.
  std::vector<MotBox> gt, pred;
  for (int f = 1; f <= 6; ++f) {
    gt.push_back(box(f, f <= 3 ? 1 : 2, 0));
    pred.push_back(box(f, 5, 0));
  }
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.id_switches, 0);
  EXPECT_DOUBLE_EQ(s.mota, 1.0);
  EXPECT_DOUBLE_EQ(s.idf1, 0.5);  // 2 * 3 / (6 + 6)
  EXPECT_DOUBLE_EQ(s.idr, 0.5);
  EXPECT_DOUBLE_EQ(s.idp, 0.5);
}

// The single- and two-object cases of py-motmetrics' own test suite (tests/test_metrics.py,
// test_kscore_* and test_correct_average), with their expected MOTA, IDF1 and switches. Each
// frame lists its objects and, per hypothesis, the object it overlaps (0: none). An object
// sits at x = 100 * id; a hypothesis is put on its object's box, or far from everything.
struct Frame {
  std::vector<int> objects;
  std::vector<std::pair<int, int>> hyps;  // (hypothesis id, object it overlaps or 0)
};
MotScore score_frames(const std::vector<Frame>& frames) {
  std::vector<MotBox> gt, pred;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const int frame = static_cast<int>(f) + 1;
    for (int o : frames[f].objects)
      gt.push_back(box(frame, o, 100.0 * o));
    for (const auto& [h, o] : frames[f].hyps)
      pred.push_back(box(frame, h, o > 0 ? 100.0 * o : 5000.0 + 100 * h));
  }
  return score_boxes(pred, gt);
}

TEST(MotScore, AgreesWithPyMotmetricsOwnCases) {
  struct Case {
    const char* name;
    std::vector<Frame> frames;
    double mota, idf1;
    long long switches;
  };
  const int a = 1, b = 2, c = 3, d = 4;
  std::vector<Case> cases;
  {  // kscore_1: hypothesis b for one frame in the middle
    Case k{"kscore_1", {}, 0.8, 0.9, 2};
    for (int f = 0; f < 10; ++f)
      k.frames.push_back({{1}, {{f != 5 ? a : b, 1}}});
    cases.push_back(k);
  }
  {  // kscore_2: a, then b, then c
    Case k{"kscore_2", {}, 0.8, 0.4, 2};
    for (int f = 0; f < 10; ++f)
      k.frames.push_back({{1}, {{f < 4 ? a : (f < 7 ? b : c), 1}}});
    cases.push_back(k);
  }
  {  // kscore_4: a new hypothesis every frame
    Case k{"kscore_4", {}, 0.1, 0.1, 9};
    for (int f = 0; f < 10; ++f)
      k.frames.push_back({{1}, {{10 + f, 1}}});
    cases.push_back(k);
  }
  {  // kscore_6
    Case k{"kscore_6", {}, 0.5, 0.625, 1};
    for (int f = 0; f < 10; ++f) {
      Frame fr{{1}, {}};
      if (f >= 2 && f <= 6) fr.hyps.push_back({a, 1});
      if (f == 7) fr.hyps.push_back({b, 1});
      k.frames.push_back(fr);
    }
    cases.push_back(k);
  }
  {  // kscore_8: object 1 a then b, object 2 b then c; object 1 leaves for the last 2 frames
    Case k{"kscore_8", {}, 0.875, 0.625, 2};
    for (int f = 0; f < 9; ++f) {
      if (f < 3)
        k.frames.push_back({{1, 2}, {{a, 1}, {b, 2}}});
      else if (f < 7)
        k.frames.push_back({{1, 2}, {{b, 1}, {c, 2}}});
      else
        k.frames.push_back({{2}, {{c, 2}}});
    }
    cases.push_back(k);
  }
  {  // kscore_10: as kscore_9 with the last frame's object gone (a false positive)
    Case k{"kscore_10", {}, 0.8, 0.580645161290, 2};
    for (int f = 0; f < 9; ++f) {
      if (f < 3)
        k.frames.push_back({{1, 2}, {{a, 1}, {d, 2}}});
      else if (f < 7)
        k.frames.push_back({{1, 2}, {{b, 1}, {c, 2}}});
      else if (f == 7)
        k.frames.push_back({{2}, {{c, 2}}});
      else
        k.frames.push_back({{}, {{c, 0}}});
    }
    cases.push_back(k);
  }
  {  // kscore_11: one hypothesis moves from object 1 to object 2 (no switch: 2 is new to it)
    Case k{"kscore_11", {}, 0.5, 0.380952380952, 0};
    for (int f = 0; f < 7; ++f)
      k.frames.push_back({{1, 2}, {{a, f < 4 ? 1 : 2}}});
    cases.push_back(k);
  }
  {  // kscore_12: object 1 then object 2, one hypothesis
    Case k{"kscore_12", {}, 1.0, 0.555555555556, 0};
    for (int f = 0; f < 9; ++f)
      k.frames.push_back({{f < 5 ? 1 : 2}, {{a, f < 5 ? 1 : 2}}});
    cases.push_back(k);
  }
  {  // correct_average (Bernardin & Stiefelhagen, fig. 3)
    Case k{"correct_average", {}, 0.2, 0.0, 0};
    for (int f = 0; f < 4; ++f)
      k.frames.push_back({{1, 2, 3, 4}, {}});
    for (int f = 0; f < 4; ++f)
      k.frames.push_back({{4}, {{4, 4}}});
    k.idf1 = 2.0 * 4 / (20 + 4);
    cases.push_back(k);
  }
  for (const Case& k : cases) {
    const MotScore s = score_frames(k.frames);
    EXPECT_NEAR(s.mota, k.mota, 1e-9) << k.name;
    EXPECT_NEAR(s.idf1, k.idf1, 1e-9) << k.name;
    EXPECT_EQ(s.id_switches, k.switches) << k.name;
  }
}

TEST(MotScore, ConfZeroGroundTruthIsNotScored) {
  // Object 2 is marked conf 0: it is neither missed nor matched; a tracker box over it is a
  // false positive (as TrackEval and py-motmetrics score MOT15).
  const std::vector<MotBox> gt = eval::parse_mot(
      "1,1,0,0,10,10,1\n1,2,50,0,10,10,0\n"
      "2,2,50,0,10,10,0\n",
      "gt");
  const std::vector<MotBox> pred = {box(1, 1, 0), box(1, 2, 50), box(2, 2, 50)};
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.gt_boxes, 1);
  EXPECT_EQ(s.objects, 1);
  EXPECT_EQ(s.fp, 2);
  EXPECT_EQ(s.fn, 0);
  EXPECT_EQ(s.frames, 2);
  EXPECT_DOUBLE_EQ(s.mota, -1.0);  // 1 - 2/1
}

TEST(MotScore, ClassColumnsFollowMotChallengePreprocessing) {
  // frame,id,x,y,w,h,conf,class,visibility: a pedestrian (1), a static person (7, distractor)
  // and a car (3). The tracker box on the distractor is removed; the one on the car is a FP.
  const std::vector<MotBox> gt = eval::parse_mot(
      "1,1,0,0,10,10,1,1,1\n"
      "1,2,50,0,10,10,1,7,0.5\n"
      "1,3,100,0,10,10,1,3,1\n",
      "gt");
  const std::vector<MotBox> pred = {box(1, 1, 0), box(1, 2, 51), box(1, 3, 100)};
  const MotScore s = score_boxes(pred, gt);
  EXPECT_EQ(s.gt_boxes, 1);
  EXPECT_EQ(s.pred_boxes, 2);
  EXPECT_EQ(s.matches, 1);
  EXPECT_EQ(s.fp, 1);
  EXPECT_DOUBLE_EQ(s.mota, 0.0);
  // Ten columns (MOT15 world coordinates): the eighth is not a class, nothing is removed.
  const std::vector<MotBox> mot15 = eval::parse_mot("1,1,0,0,10,10,1,7,-1,-1\n", "gt");
  EXPECT_EQ(mot15[0].object_class, 0);
  EXPECT_EQ(score_boxes({box(1, 4, 0)}, mot15).matches, 1);
}

TEST(MotScore, EmptyGroundTruthThrows) {
  EXPECT_NE(test::error_message([] { score_boxes({box(1, 1, 0)}, {}); }).find("no box"),
            std::string::npos);
  const auto zero = eval::parse_mot("1,1,0,0,10,10,0\n", "gt");
  EXPECT_NE(test::error_message([&] { score_boxes({}, zero); }).find("no box"), std::string::npos);
}

TEST(MotScore, NoPredictionsIsAllMisses) {
  const MotScore s = score_boxes({}, {box(1, 1, 0), box(2, 1, 0), box(2, 2, 30)});
  EXPECT_EQ(s.fn, 3);
  EXPECT_DOUBLE_EQ(s.mota, 0.0);
  EXPECT_DOUBLE_EQ(s.idf1, 0.0);
  EXPECT_DOUBLE_EQ(s.motp, 0.0);
}

TEST(MotIo, ParsesSeparatorsAndSorts) {
  const std::vector<MotBox> rows =
      eval::parse_mot("2,1,1.5,2,3,4,0.9,-1,-1,-1\r\n\n1 7 0 0 5 5\n1.0,\t3 ,0,0,5,5,1\n", "f");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].frame, 1);
  EXPECT_EQ(rows[0].id, 3);
  EXPECT_EQ(rows[1].id, 7);
  EXPECT_EQ(rows[2].frame, 2);
  EXPECT_DOUBLE_EQ(rows[2].box.x, 1.5);
  EXPECT_DOUBLE_EQ(rows[2].conf, 0.9);
  EXPECT_DOUBLE_EQ(rows[1].conf, 1.0);  // no conf column
}

TEST(MotIo, RejectsBadRows) {
  const std::pair<const char*, const char*> cases[] = {
      {"1,1,0,0,10\n", "expected 6 to 10 fields"},
      {"1,1,0,0,10,10,1,-1,-1,-1,5\n", "expected 6 to 10 fields"},
      {"0,1,0,0,10,10\n", "frame '0'"},
      {"1,-2,0,0,10,10\n", "id '-2'"},
      {"1,1.5,0,0,10,10\n", "id '1.5'"},
      {"1,1,zero,0,10,10\n", "x 'zero'"},
      {"1,1,0,0,nan,10\n", "w 'nan'"},
      {"1,1,0,0,-3,10\n", "negative box size"},
      {"1,1,0,0,10,10,1,14,1\n", "class '14'"},
      {"1,1,0,0,10,10,1,1,1.5\n", "visibility '1.5'"},
      {"1,1,0,0,10,10\n2,1,0,0,1,1\n1,1,5,5,10,10\n", "id 1 appears twice in frame 1"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string message = test::error_message([&] { eval::parse_mot(text, "in.txt"); });
    EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
    EXPECT_EQ(message.rfind("in.txt:", 0), 0u) << message;
  }
  EXPECT_NE(test::error_message([] {
              eval::parse_mot("1,1,0,0,10,10\n1,1,0,0,1,1\n", "f");
            }).find("f:2:"),
            std::string::npos);
}

class MotFileTest : public test::TempDirTest {};

TEST_F(MotFileTest, WritesAndReadsBack) {
  std::vector<MotBox> boxes = {box(2, 4, 1.25, 2.5, 30, 40), box(1, 9, -3, 7.126, 5, 6)};
  boxes[0].conf = 0.75;
  eval::write_mot(path("mot.txt"), boxes);
  EXPECT_EQ(test::read_text(path("mot.txt")),
            "1,9,-3.00,7.13,5.00,6.00,1,-1,-1,-1\n2,4,1.25,2.50,30.00,40.00,0.75,-1,-1,-1\n");
  const std::vector<MotBox> back = eval::read_mot(path("mot.txt"), "tracker output");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].id, 4);
  EXPECT_DOUBLE_EQ(back[1].box.width, 30);
  EXPECT_DOUBLE_EQ(back[1].conf, 0.75);
  EXPECT_NE(test::error_message([&] {
              eval::read_mot(path("none.txt"), "ground truth");
            }).find("cannot read ground truth"),
            std::string::npos);
}

}  // namespace
