#include "report/plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace roiflow::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A minimal well-formedness check: every element closes in order, attributes are quoted, and
// no bare '&' or '<' sits in text.
bool well_formed(const std::string& xml, std::string& why) {
  std::vector<std::string> open;
  std::size_t i = 0;
  while (i < xml.size()) {
    if (xml[i] == '&') {
      const std::size_t semi = xml.find(';', i);
      const std::string entity = xml.substr(i, semi == std::string::npos ? 6 : semi - i + 1);
      if (!std::regex_match(entity, std::regex("&(amp|lt|gt|quot|#39);"))) {
        why = "bad entity " + entity;
        return false;
      }
      i = semi + 1;
      continue;
    }
    if (xml[i] != '<') {
      ++i;
      continue;
    }
    const std::size_t end = xml.find('>', i);
    if (end == std::string::npos) {
      why = "unterminated tag";
      return false;
    }
    const std::string tag = xml.substr(i + 1, end - i - 1);
    i = end + 1;
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    if (tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1)) {
        why = "unexpected </" + tag.substr(1) + ">";
        return false;
      }
      open.pop_back();
      continue;
    }
    if (tag.find('<') != std::string::npos) {
      why = "'<' inside a tag";
      return false;
    }
    // Attributes: name="value" pairs only.
    const std::size_t name_end = tag.find_first_of(" /");
    const std::string name = tag.substr(0, name_end);
    const std::string attrs = name_end == std::string::npos ? "" : tag.substr(name_end);
    if (!std::regex_match(attrs, std::regex(R"((\s+[a-zA-Z][a-zA-Z0-9:-]*="[^"<]*")*\s*/?)"))) {
      why = "bad attributes in <" + tag + ">";
      return false;
    }
    if (tag.back() != '/') open.push_back(name);
  }
  if (!open.empty()) why = "<" + open.back() + "> never closed";
  return open.empty();
}

struct Box {
  double x = 0, y = 0, w = 0, h = 0;
};

double attr(const std::string& element, const std::string& name) {
  std::smatch m;
  const std::regex re("\\s" + name + "=\"([-0-9.eE]+)\"");
  if (!std::regex_search(element, m, re)) {
    ADD_FAILURE() << "no " << name << " in " << element;
    return kNaN;
  }
  return std::stod(m[1]);
}

std::vector<std::string> elements(const std::string& svg, const std::string& pattern) {
  std::vector<std::string> found;
  const std::regex re(pattern);
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator();
       ++it)
    found.push_back(it->str());
  return found;
}

std::vector<Box> plot_areas(const std::string& svg) {
  std::vector<Box> boxes;
  for (const std::string& e : elements(svg, "<rect class=\"plot-area\"[^>]*>"))
    boxes.push_back({attr(e, "x"), attr(e, "y"), attr(e, "width"), attr(e, "height")});
  return boxes;
}

std::vector<std::pair<double, double>> markers(const std::string& svg) {
  std::vector<std::pair<double, double>> points;
  for (const std::string& e : elements(svg, "<circle class=\"marker\"[^>]*>"))
    points.emplace_back(attr(e, "cx"), attr(e, "cy"));
  return points;
}

Plot two_series_plot() {
  Plot plot;
  plot.title = "Error vs patch size";
  plot.x_label = "patch size (px)";
  PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "AAE (deg)";
  panel.y2_label = "EPE (px)";
  panel.series.push_back({"AAE", {3, 5, 7, 9}, {9.5, 6.0, 5.2, 5.6}});
  panel.series.push_back({"EPE", {3, 5, 7, 9}, {0.8, 0.5, 0.42, 0.47}, PlotAxis::Right});
  return plot;
}

TEST(NiceTicks, StepsAreOneTwoOrFiveTimesAPowerOfTenAndEncloseTheData) {
  struct Case {
    double lo, hi;
  };
  for (const Case c : {Case{0, 7.3}, Case{0.0013, 0.0089}, Case{-3.2, 41}, Case{3, 31},
                       Case{5.17, 5.94}, Case{120, 12000}}) {
    SCOPED_TRACE(std::to_string(c.lo) + ".." + std::to_string(c.hi));
    const Ticks t = nice_ticks(c.lo, c.hi);
    const double mantissa = t.step / std::pow(10.0, std::floor(std::log10(t.step)));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                std::abs(mantissa - 5) < 1e-9)
        << t.step;
    EXPECT_LE(t.lo, c.lo);
    EXPECT_GE(t.hi, c.hi);
    EXPECT_LT(t.hi - t.lo, 3 * (c.hi - c.lo) + 2 * t.step);  // not absurdly loose
    ASSERT_GE(t.values.size(), 3u);
    EXPECT_LE(t.values.size(), 12u);
    EXPECT_DOUBLE_EQ(t.values.front(), t.lo);
    EXPECT_NEAR(t.values.back(), t.hi, t.step * 1e-9);
    EXPECT_NEAR(std::remainder(t.lo, t.step), 0.0, t.step * 1e-9);
  }
  const Ticks zero_to_seven = nice_ticks(0, 7.3);
  EXPECT_DOUBLE_EQ(zero_to_seven.lo, 0);
  EXPECT_DOUBLE_EQ(zero_to_seven.hi, 8);
  EXPECT_DOUBLE_EQ(zero_to_seven.step, 1);
  const Ticks patches = nice_ticks(3, 31);  // the sweep's patch axis: 0..35 by 5, not 0..40
  EXPECT_DOUBLE_EQ(patches.lo, 0);
  EXPECT_DOUBLE_EQ(patches.hi, 35);
  EXPECT_DOUBLE_EQ(patches.step, 5);
}

TEST(NiceTicks, ASingleValueGetsARangeAroundItAndBadRangesThrow) {
  const Ticks t = nice_ticks(5, 5);
  EXPECT_LT(t.lo, 5);
  EXPECT_GT(t.hi, 5);
  const Ticks z = nice_ticks(0, 0);
  EXPECT_DOUBLE_EQ(z.lo, 0);
  EXPECT_GT(z.hi, 0);
  EXPECT_NE(test::error_message([] { nice_ticks(2, 1); }).find("[2, 1]"), std::string::npos);
  EXPECT_NE(test::error_message([] { nice_ticks(kNaN, 1); }).find("nan"), std::string::npos);
}

TEST(PlotSvg, IsWellFormedAndCarriesTitleLabelsAndLegend) {
  Plot plot = two_series_plot();
  plot.title = "Error <AAE> & EPE";
  const std::string svg = plot_svg(plot);
  std::string why;
  EXPECT_TRUE(well_formed(svg, why)) << why;
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_NE(svg.find("Error &lt;AAE&gt; &amp; EPE"), std::string::npos);
  EXPECT_NE(svg.find(">patch size (px)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">AAE (deg)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">EPE (px)</text>"), std::string::npos);
  EXPECT_NE(svg.find("class=\"legend\""), std::string::npos);
  EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos);  // the right-axis series
  EXPECT_EQ(plot_areas(svg).size(), 1u);
}

TEST(PlotSvg, PointsMapIntoThePlotBoxInOrder) {
  Plot plot = two_series_plot();
  PlotPanel& time = plot.panels.emplace_back();
  time.y_label = "time (ms per pair)";
  time.y_from_zero = true;
  time.series.push_back({"ms", {3, 5, 7, 9}, {10, 11, 12, 13}});
  const std::string svg = plot_svg(plot);
  const std::vector<Box> areas = plot_areas(svg);
  ASSERT_EQ(areas.size(), 2u);
  EXPECT_GT(areas[1].y, areas[0].y + areas[0].h);  // stacked, not overlapping
  const auto points = markers(svg);
  ASSERT_EQ(points.size(), 12u);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Box& box = areas[i < 8 ? 0 : 1];
    EXPECT_GE(points[i].first, box.x - 1e-6);
    EXPECT_LE(points[i].first, box.x + box.w + 1e-6);
    EXPECT_GE(points[i].second, box.y - 1e-6);
    EXPECT_LE(points[i].second, box.y + box.h + 1e-6);
  }
  // AAE: x increasing -> cx increasing; 9.5 is the highest value, so the smallest cy.
  EXPECT_LT(points[0].first, points[1].first);
  EXPECT_LT(points[1].first, points[2].first);
  EXPECT_LT(points[0].second, points[1].second);
  EXPECT_GT(points[2].second, points[3].second);  // 5.2 < 5.6 -> lower on screen
  // Same x on both axes, same column; the time series rises steadily.
  EXPECT_DOUBLE_EQ(points[0].first, points[4].first);
  EXPECT_DOUBLE_EQ(points[0].first, points[8].first);
  EXPECT_NEAR(points[8].second - points[9].second, points[10].second - points[11].second, 0.02);
  // y_from_zero: 10..13 ms over an axis from 0 puts the points in the upper part of the box.
  EXPECT_LT(points[8].second, areas[1].y + areas[1].h / 2);
}

TEST(PlotSvg, UndrawablePointsAreSkippedWithAGap) {
  Plot plot;
  plot.title = "gap";
  plot.x_label = "x (px)";
  PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "y (ms)";
  panel.series.push_back(
      {"s", {1, 2, 3, 4, 5}, {1, 2, kNaN, 4, std::numeric_limits<double>::infinity()}});
  const std::string svg = plot_svg(plot);
  EXPECT_EQ(markers(svg).size(), 3u);
  const std::vector<std::string> paths = elements(svg, "<path d=\"[^\"]*\"");
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_EQ(std::count(paths[0].begin(), paths[0].end(), 'M'), 2);  // broken at the NaN
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(PlotSvg, LogAxisHasATickPerDecadeAndSkipsNonPositiveX) {
  Plot plot;
  plot.title = "lambda";
  plot.x_label = "lambda";
  plot.x_log = true;
  PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "EPE (px)";
  panel.series.push_back({"EPE", {0, 1e-8, 1e-6, 1e-4}, {1, 0.5, 0.4, 0.6}});
  const std::string svg = plot_svg(plot);
  EXPECT_EQ(markers(svg).size(), 3u);
  EXPECT_EQ(elements(svg, "<text class=\"xtick\"").size(), 5u);  // 1e-08 .. 0.0001
  EXPECT_NE(svg.find(">1e-08</text>"), std::string::npos);
  const auto points = markers(svg);
  // Equal decades, equal spacing.
  EXPECT_NEAR(points[1].first - points[0].first, points[2].first - points[1].first, 0.02);
}

TEST(PlotSvg, InconsistentInputThrowsNamingIt) {
  Plot no_panel;
  no_panel.title = "empty";
  EXPECT_NE(test::error_message([&] { plot_svg(no_panel); }).find("'empty' has no panel"),
            std::string::npos);

  Plot mismatch = two_series_plot();
  mismatch.panels[0].series[0].y.pop_back();
  EXPECT_NE(test::error_message([&] {
              plot_svg(mismatch);
            }).find("series 'AAE' has 4 x values but 3 y values"),
            std::string::npos);

  Plot all_nan = two_series_plot();
  for (PlotSeries& s : all_nan.panels[0].series)
    s.y.assign(s.x.size(), kNaN);
  EXPECT_NE(test::error_message([&] { plot_svg(all_nan); }).find("no point to draw"),
            std::string::npos);

  Plot no_right_label = two_series_plot();
  no_right_label.panels[0].y2_label.clear();
  EXPECT_NE(test::error_message([&] { plot_svg(no_right_label); }).find("right axis"),
            std::string::npos);

  Plot narrow = two_series_plot();
  narrow.width = 10;
  EXPECT_NE(test::error_message([&] { plot_svg(narrow); }).find("width"), std::string::npos);
}

class PlotFileTest : public test::TempDirTest {};

TEST_F(PlotFileTest, WritesTheSvgAtomicallyAndFailsOnAMissingFolder) {
  write_plot_svg(path("p.svg"), two_series_plot());
  std::ifstream in(path("p.svg"));
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(text, plot_svg(two_series_plot()));
  const std::string missing = path("no/such/p.svg");
  EXPECT_NE(test::error_message([&] { write_plot_svg(missing, two_series_plot()); }).find(missing),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(missing));
}

}  // namespace
}  // namespace roiflow::report
