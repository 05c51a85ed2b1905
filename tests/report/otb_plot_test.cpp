// OTB success and precision plots: one curve per tracker, best first, the score in the legend.
#include "report/otb_plot.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.hpp"

namespace roiflow::report {
namespace {

eval::BenchmarkRow row(const std::string& tracker, double iou_share) {
  // Every frame has IoU 0.5 for a share `iou_share` of frames, else 0: success is that share for
  // thresholds below 0.5 (k = 0..9), 0 above; AUC = 10 * share / 21.
  eval::BenchmarkRow r;
  r.sequence = "mean";
  r.tracker = tracker;
  r.sequences = 3;
  for (int k = 0; k < eval::kSuccessThresholds; ++k)
    r.curves.success.push_back(k < 10 ? iou_share : 0.0);
  for (int t = 0; t < eval::kPrecisionThresholds; ++t)
    r.curves.precision.push_back(t < 10 ? 0.0 : 1.0 - iou_share / 2);
  r.auc = eval::curve_auc(r.curves.success);
  r.precision20 = r.curves.precision[20];
  return r;
}

TEST(OtbPlotTest, SuccessPlotOrdersTrackersByAucAndNamesIt) {
  const std::vector<eval::BenchmarkRow> rows = {row("slow", 0.42), row("best", 0.84)};
  const Plot plot = success_plot(rows);
  EXPECT_EQ(plot.title, "Success plots of OPE (3 sequences)");
  ASSERT_EQ(plot.panels.size(), 1u);
  const std::vector<PlotSeries>& s = plot.panels[0].series;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "best [0.400]");  // 10 * 0.84 / 21
  EXPECT_EQ(s[1].name, "slow [0.200]");
  ASSERT_EQ(s[0].x.size(), 21u);
  EXPECT_DOUBLE_EQ(s[0].x[10], 0.5);
  EXPECT_DOUBLE_EQ(s[0].y[9], 0.84);
  const std::string svg = plot_svg(plot);
  EXPECT_NE(svg.find("best [0.400]"), std::string::npos);
  EXPECT_NE(svg.find("overlap threshold"), std::string::npos);
}

TEST(OtbPlotTest, PrecisionPlotOrdersTrackersByPrecisionAt20) {
  const std::vector<eval::BenchmarkRow> rows = {row("a", 0.84), row("b", 0.42)};
  const Plot plot = precision_plot(rows);
  const std::vector<PlotSeries>& s = plot.panels[0].series;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "b [0.790]");  // 1 - 0.42 / 2
  EXPECT_EQ(s[1].name, "a [0.580]");
  ASSERT_EQ(s[0].x.size(), 51u);
  EXPECT_DOUBLE_EQ(s[0].x[50], 50.0);
  EXPECT_NE(plot_svg(plot).find("location error threshold"), std::string::npos);
}

TEST(OtbPlotTest, BadRowsThrow) {
  EXPECT_NE(test::error_message([] { success_plot({}); }).find("no tracker"), std::string::npos);
  eval::BenchmarkRow short_row = row("x", 0.5);
  short_row.curves.success.pop_back();
  EXPECT_NE(test::error_message([&] { precision_plot({short_row}); }).find("20 success"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::report
