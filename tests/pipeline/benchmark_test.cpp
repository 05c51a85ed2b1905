// roiflow benchmark's run: every tracker on every sequence of a synthetic OTB folder (exact
// ground truth), the outputs, and the checks that fail before any tracker runs.
#include "pipeline/benchmark.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "eval/otb_score.hpp"
#include "eval/track_log.hpp"
#include "otb_test_tree.hpp"
#include "test_util.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;
using test::error_message;

class BenchmarkTest : public test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    // An OTB sequence with space-separated values and two absent frames, and a gray TinyTLP one
    // with one absent frame.
    test::OtbSequenceSpec otb;
    otb.frames = 20;
    otb.seed = 2;
    otb.absent = {7, 8};
    otb.separator = ' ';
    test::write_otb_sequence(dir_ / "set" / "otb", otb);
    test::OtbSequenceSpec tlp;
    tlp.frames = 16;
    tlp.seed = 5;
    tlp.tiny_tlp = true;
    tlp.absent = {10};
    tlp.gray = true;
    test::write_otb_sequence(dir_ / "set" / "tlp", tlp);
    fs::create_directories(dir_ / "set" / "readme");  // not a sequence
  }

  BenchmarkOptions options(std::vector<std::string> trackers) const {
    BenchmarkOptions o;
    o.dir = path("set");
    o.trackers = std::move(trackers);
    o.threads = 2;
    return o;
  }
};

TEST_F(BenchmarkTest, RunsEveryTrackerOnEverySequence) {
  const std::vector<std::string> all = {"roiflow", "csrt", "kcf", "mosse", "medianflow"};
  std::vector<std::string> reported;
  BenchmarkOptions o = options(all);
  o.on_sequence = [&](const std::string& line) { reported.push_back(line); };
  const BenchmarkResult r = run_benchmark(o);
  ASSERT_EQ(r.rows.size(), 10u);
  ASSERT_EQ(r.means.size(), 5u);
  EXPECT_EQ(r.skipped, std::vector<std::string>{"readme"});
  ASSERT_EQ(reported.size(), 2u);
  EXPECT_NE(reported[0].find(": "), std::string::npos);
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const eval::BenchmarkRow& row = r.rows[i];
    SCOPED_TRACE(row.sequence + " " + row.tracker);
    EXPECT_EQ(row.sequence, i < 5 ? "otb" : "tlp");
    EXPECT_EQ(row.tracker, all[i % 5]);
    EXPECT_EQ(row.frames, i < 5 ? 20 : 16);
    EXPECT_EQ(row.scored, i < 5 ? 18 : 15);  // absent frames are not scored
    EXPECT_TRUE(std::isfinite(row.fps) && row.fps > 0) << row.fps;
    EXPECT_GE(row.auc, 0.0);
    EXPECT_LE(row.auc, 20.0 / 21);
    // Every tracker reports the ground-truth box on the first frame: at least 1/15 of the
    // frames have IoU 1 (the box rounded for CSRT and KCF: IoU > 0.9).
    EXPECT_GE(row.curves.success[18], 1.0 / row.scored - 1e-9);
  }
  // A smooth synthetic run: roiflow and CSRT follow the vehicle closely.
  for (const eval::BenchmarkRow& m : r.means) {
    if (m.tracker == "roiflow" || m.tracker == "csrt") {
      EXPECT_GT(m.auc, 0.6) << m.tracker;
      EXPECT_GT(m.precision20, 0.9) << m.tracker;
    }
  }
  // The same scores one sequence at a time.
  BenchmarkOptions serial = options({"roiflow", "csrt"});
  serial.threads = 1;
  const BenchmarkResult s = run_benchmark(serial);
  ASSERT_EQ(s.rows.size(), 4u);
  EXPECT_DOUBLE_EQ(s.rows[0].auc, r.rows[0].auc);
  EXPECT_DOUBLE_EQ(s.rows[1].auc, r.rows[1].auc);
  EXPECT_DOUBLE_EQ(s.rows[2].auc, r.rows[5].auc);
  EXPECT_DOUBLE_EQ(s.rows[3].auc, r.rows[6].auc);
}

TEST_F(BenchmarkTest, SequencesAndMaxFramesNarrowTheRun) {
  BenchmarkOptions o = options({"mosse"});
  o.sequences = {"tlp"};
  o.max_frames = 5;
  const BenchmarkResult r = run_benchmark(o);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].sequence, "tlp");
  EXPECT_EQ(r.rows[0].frames, 5);
  EXPECT_EQ(r.rows[0].scored, 5);
  // One sequence's own folder.
  BenchmarkOptions one = options({"roiflow"});
  one.dir = path("set/otb");
  one.max_frames = 3;
  const BenchmarkResult single = run_benchmark(one);
  ASSERT_EQ(single.rows.size(), 1u);
  EXPECT_EQ(single.rows[0].sequence, "otb");
}

TEST_F(BenchmarkTest, WritesTheTablesAndPlots) {
  BenchmarkOptions o = options({"roiflow", "kcf"});
  o.max_frames = 6;
  const BenchmarkResult r = run_benchmark(o);
  const std::vector<std::string> written = write_benchmark(r, path("out/nested"));
  ASSERT_EQ(written.size(), 4u);
  const std::vector<std::string> csv =
      test::lines_of(test::read_text(path("out/nested/benchmark.csv")));
  ASSERT_EQ(csv.size(), 1u + 4u + 2u);
  EXPECT_EQ(csv[1].rfind("otb,roiflow,6,6,", 0), 0u) << csv[1];
  EXPECT_EQ(csv[5].rfind("mean,roiflow,12,12,", 0), 0u) << csv[5];
  const std::string md = test::read_text(path("out/nested/benchmark.md"));
  EXPECT_EQ(md, eval::format_benchmark_markdown(r.rows, r.means));
  for (const char* svg : {"out/nested/success.svg", "out/nested/precision.svg"}) {
    const std::string text = test::read_text(path(svg));
    EXPECT_NE(text.find("</svg>"), std::string::npos) << svg;
    EXPECT_NE(text.find("roiflow ["), std::string::npos) << svg;
    EXPECT_NE(text.find("kcf ["), std::string::npos) << svg;
  }
  for (const auto& e : fs::directory_iterator(path("out/nested")))
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out/nested/tracks")));

  // With tracks: every run's log, which scores like its row (to the log's 2-decimal rounding).
  const std::vector<std::string> with_tracks = write_benchmark(r, path("out/t"), true);
  ASSERT_EQ(with_tracks.size(), 5u);
  EXPECT_EQ(with_tracks[4], path("out/t/tracks"));
  ASSERT_EQ(r.runs.size(), r.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const eval::BenchmarkRow& row = r.rows[i];
    SCOPED_TRACE(row.sequence + " " + row.tracker);
    const std::vector<eval::TrackRecord> log =
        eval::read_track_csv(path("out/t/tracks/" + row.sequence + "/" + row.tracker + ".csv"));
    ASSERT_EQ(static_cast<long long>(log.size()), row.frames);
    EXPECT_EQ(log[0].box, r.runs[i].boxes[0]);
    long long lost = 0;
    double ms = 0;
    for (const eval::TrackRecord& rec : log) {
      lost += rec.lost ? 1 : 0;
      ms += rec.ms;
    }
    EXPECT_EQ(lost, row.lost);
    EXPECT_NEAR(ms / 1000.0, row.cpu_s, 1e-3 * row.frames);  // ms to 3 decimals per frame
    const std::vector<cv::Rect2f> truth =
        eval::read_ground_truth(path("set/" + row.sequence + "/groundtruth_rect.txt"));
    EXPECT_NEAR(eval::score(eval::track_boxes(log), truth).auc, row.auc, 0.01);
  }
}

// --init-shift: every tracker starts from the first box moved, and is scored against the true
// boxes (so the first frame's IoU is below 1).
TEST_F(BenchmarkTest, InitShiftMovesEveryTrackersStartBox) {
  const cv::Rect2f first = eval::find_otb_sequences(path("set")).front().truth.front();
  BenchmarkOptions o = options({"roiflow", "mosse"});
  o.sequences = {"otb"};
  o.max_frames = 3;
  const BenchmarkResult plain = run_benchmark(o);
  o.init_shift = {3.f, -2.f};
  const BenchmarkResult shifted = run_benchmark(o);
  ASSERT_EQ(shifted.runs.size(), 2u);
  const cv::Rect2f roiflow_start = shifted.runs[0].boxes.front();
  EXPECT_NEAR(roiflow_start.x, first.x + 3.f, 1e-4);
  EXPECT_NEAR(roiflow_start.y, first.y - 2.f, 1e-4);
  EXPECT_NEAR(roiflow_start.width, first.width, 1e-4);
  EXPECT_NEAR(roiflow_start.height, first.height, 1e-4);
  // MOSSE rounds its box to whole pixels.
  EXPECT_NEAR(shifted.runs[1].boxes.front().x, first.x + 3.f, 1.0);
  EXPECT_NEAR(shifted.runs[1].boxes.front().y, first.y - 2.f, 1.0);
  EXPECT_NEAR(plain.runs[0].boxes.front().x, first.x, 1e-4);
  EXPECT_LT(shifted.rows[0].mean_iou, plain.rows[0].mean_iou);
}

TEST_F(BenchmarkTest, BadInputFailsBeforeAnyTrackerRuns) {
  const auto fails = [&](BenchmarkOptions o, const std::string& expected) {
    SCOPED_TRACE(expected);
    bool ran = false;
    o.on_sequence = [&](const std::string&) { ran = true; };
    const std::string message = error_message([&] { run_benchmark(o); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_FALSE(ran);
  };
  fails(options({"roiflow", "goturn"}), "unknown tracker 'goturn' (known: roiflow, csrt");
  fails(options({"kcf", "kcf"}), "'kcf' is listed twice");
  fails(options({}), "no tracker");
  BenchmarkOptions o = options({"roiflow"});
  o.sequences = {"otb", "nope"};
  fails(o, "no sequence 'nope'");
  o = options({"roiflow"});
  o.threads = 0;
  fails(o, "threads 0");
  o = options({"roiflow"});
  o.dir = path("nowhere");
  fails(o, "not a directory");
  o = options({"roiflow"});
  o.init_shift = {0.f, std::nanf("")};
  fails(o, "init shift must be finite");
  o = options({"roiflow"});
  o.init_shift = {400.f, 0.f};  // the frames are 160 wide
  fails(o, "shifted by --init-shift leaves the 160x120 frame");

  // One box too many for the frames.
  std::ofstream(path("set/otb/groundtruth_rect.txt"), std::ios::app) << "1 2 3 4\n";
  fails(options({"roiflow"}), "otb: groundtruth_rect.txt holds 21 boxes but the sequence has 20");
  // A first box outside the frame.
  test::write_otb_sequence(dir_ / "set" / "otb", test::OtbSequenceSpec{});
  std::string truth = test::read_text(path("set/otb/groundtruth_rect.txt"));
  truth = "500,500,10,10" + truth.substr(truth.find('\n'));
  std::ofstream(path("set/otb/groundtruth_rect.txt")) << truth;
  fails(options({"roiflow"}), "lies outside the 160x120 frame");
}

TEST_F(BenchmarkTest, OutMustBeAFolderThatCanBeMade) {
  std::ofstream(path("file")) << "x";
  EXPECT_NE(error_message([&] { check_benchmark_out(path("file")); }).find("not a directory"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              check_benchmark_out(path("file/sub"));
            }).find("is not a writable directory"),
            std::string::npos);
  EXPECT_EQ(error_message([&] { check_benchmark_out(path("new/deeper")); }), "no exception");
  EXPECT_FALSE(fs::exists(path("new")));  // checked, not made
}

}  // namespace
}  // namespace roiflow::pipeline
