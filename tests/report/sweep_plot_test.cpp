#include "report/sweep_plot.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.hpp"

namespace roiflow::report {
namespace {

using eval::SweepParam;
using eval::SweepRow;
using test::read_text;

class SweepPlotTest : public test::TempDirTest {};

TEST_F(SweepPlotTest, PlotsErrorAndTimeAgainstTheValue) {
  std::vector<SweepRow> rows;
  for (int i = 1; i <= 4; ++i)
    rows.push_back({SweepParam::Iterations, double(i), 10.0 / i, 1.0 / i, 2.0 * i, 3});
  rows.push_back({SweepParam::Lambda, 1e-6, 5, 0.5, 3, 3});
  rows.push_back({SweepParam::Lambda, 1e-3, 6, 0.6, 3, 3});
  const Plot it = sweep_plot(SweepParam::Iterations, rows, "middlebury");
  ASSERT_EQ(it.panels.size(), 2u);
  EXPECT_EQ(it.panels[0].series[0].x.size(), 4u);  // only the iteration rows
  EXPECT_EQ(it.panels[1].series[0].y, (std::vector<double>{2, 4, 6, 8}));
  EXPECT_NE(it.title.find("middlebury, mean of 3 pairs"), std::string::npos);
  EXPECT_TRUE(sweep_plot(SweepParam::Lambda, rows).x_log);
  write_plot_svg(path("iterations.svg"), it);
  const std::string svg = read_text(path("iterations.svg"));
  EXPECT_NE(svg.find("run time (ms per pair)"), std::string::npos);
  EXPECT_NE(svg.find("mean EPE (px)"), std::string::npos);
  EXPECT_NE(test::error_message([&] { sweep_plot(SweepParam::Sigma, rows); }).find("sigma"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::report
