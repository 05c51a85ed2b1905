#include "pipeline/scaling.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using pipeline::ScalingMode;
using pipeline::ScalingOptions;
using pipeline::ScalingResult;
using pipeline::ScalingRow;

ScalingOptions options(ScalingMode mode) {
  ScalingOptions o;
  o.input = "synthetic:12:160x120:3";
  o.threads = {1, 2};
  o.mode = mode;
  return o;
}

TEST(Scaling, EveryModeTimesEveryThreadCountOverTheWholeInput) {
  for (const ScalingMode mode : {ScalingMode::Local, ScalingMode::Global, ScalingMode::Dense}) {
    const ScalingResult r = pipeline::run_scaling(options(mode));
    ASSERT_EQ(r.rows.size(), 2u) << pipeline::to_string(mode);
    EXPECT_EQ(r.mode, mode);
    EXPECT_NE(r.input.find("synthetic traffic (12 frames, 3 vehicles"), std::string::npos)
        << r.input;
    for (const ScalingRow& row : r.rows) {
      EXPECT_EQ(row.frames, mode == ScalingMode::Dense ? 11 : 12);
      EXPECT_GT(row.wall_s, 0);
      EXPECT_NEAR(row.fps, row.frames / row.wall_s, 1e-9);
      EXPECT_GT(row.tracker_fps, 0);
    }
    EXPECT_EQ(r.rows[0].threads, 1);
    EXPECT_EQ(r.rows[1].threads, 2);
    EXPECT_DOUBLE_EQ(r.rows[0].speedup, 1.0);
    EXPECT_DOUBLE_EQ(r.rows[1].speedup, r.rows[1].fps / r.rows[0].fps);
    EXPECT_DOUBLE_EQ(r.rows[1].efficiency, r.rows[1].speedup / 2);
  }
}

TEST(Scaling, MaxFramesAndRepeats) {
  ScalingOptions o = options(ScalingMode::Local);
  o.threads = {2};
  o.max_frames = 5;
  o.repeats = 2;
  const ScalingResult r = pipeline::run_scaling(o);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].frames, 5);
  EXPECT_DOUBLE_EQ(r.rows[0].speedup, 1.0);
}

TEST(Scaling, SpeedupAndEfficiencyAreRelativeToTheFirstRow) {
  std::vector<ScalingRow> rows(3);
  rows[0].threads = 2;
  rows[0].fps = 100;
  rows[1].threads = 4;
  rows[1].fps = 180;
  rows[2].threads = 8;
  rows[2].fps = 200;
  pipeline::fill_speedup(rows);
  EXPECT_DOUBLE_EQ(rows[0].speedup, 1.0);
  EXPECT_DOUBLE_EQ(rows[0].efficiency, 1.0);
  EXPECT_DOUBLE_EQ(rows[1].speedup, 1.8);
  EXPECT_DOUBLE_EQ(rows[1].efficiency, 0.9);
  EXPECT_DOUBLE_EQ(rows[2].speedup, 2.0);
  EXPECT_DOUBLE_EQ(rows[2].efficiency, 0.5);
}

TEST(Scaling, CsvAndPlot) {
  ScalingResult r;
  r.input = "clip";
  r.rows.resize(2);
  r.rows[0] = {1, 10, 1.0, 10.0, 50.0, 1.0, 1.0};
  r.rows[1] = {2, 10, 0.6, 16.666, 95.5, 1.6666, 0.8333};
  EXPECT_EQ(pipeline::scaling_csv(r),
            "threads,fps,tracker_fps,speedup,efficiency\n1,10.00,50.00,1.000,1.000\n"
            "2,16.67,95.50,1.667,0.833\n");
  const report::Plot plot = pipeline::scaling_plot(r);
  ASSERT_EQ(plot.panels.size(), 2u);
  EXPECT_EQ(plot.panels[1].series[1].y, (std::vector<double>{1, 2}));  // ideal
  EXPECT_NE(report::plot_svg(plot).find("speedup"), std::string::npos);
}

class ScalingFiles : public test::TempDirTest {};

TEST_F(ScalingFiles, TextTableAndTheTwoFiles) {
  ScalingResult r;
  r.input = "clip";
  r.mode = ScalingMode::Dense;
  r.rows = {{1, 10, 1.0, 10.0, 50.0, 1.0, 1.0}, {2, 10, 0.6, 16.666, 95.5, 1.6666, 0.8333}};
  EXPECT_EQ(pipeline::scaling_text(r),
            "scaling dense mode, clip\n"
            "threads      fps  tracker_fps  speedup  efficiency\n"
            "      1     10.0         50.0     1.00        1.00\n"
            "      2     16.7         95.5     1.67        0.83\n");
  const std::vector<std::string> written = pipeline::write_scaling(r, dir_.string());
  ASSERT_EQ(written, (std::vector<std::string>{path("scaling.csv"), path("scaling.svg")}));
  EXPECT_EQ(test::read_text(written[0]), pipeline::scaling_csv(r));
  EXPECT_NE(test::read_text(written[1]).find("<svg"), std::string::npos);
}

TEST(Scaling, BadOptionsThrow) {
  const auto fails = [](ScalingOptions o, const std::string& expected) {
    const std::string message = test::error_message([&] { pipeline::run_scaling(o); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  ScalingOptions o = options(ScalingMode::Local);
  o.threads = {};
  fails(o, "no thread count");
  o.threads = {1, 0};
  fails(o, "got 0");
  o.threads = {2, 1, 2};
  fails(o, "2 given twice");
  o.threads = {1};
  o.repeats = 0;
  fails(o, "repeats");
  o = options(ScalingMode::Dense);
  o.input = "synthetic:0";
  fails(o, "bad synthetic input");
  EXPECT_EQ(pipeline::scaling_mode_from_string("dense"), ScalingMode::Dense);
  EXPECT_NE(test::error_message([] { pipeline::scaling_mode_from_string("fast"); }).find("'fast'"),
            std::string::npos);
}

}  // namespace
