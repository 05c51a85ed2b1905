#include "report/annotate.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <tuple>

#include "flow/color_code.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
using report::annotate_frame;
using report::AnnotateStyle;
using report::TrackAnnotation;

constexpr int kGray = 100;

cv::Mat gray_image() {
  return cv::Mat(120, 160, CV_8UC1, cv::Scalar(kGray));
}

AnnotateStyle no_text() {
  AnnotateStyle style;
  style.text = false;
  return style;
}

TrackAnnotation with_box(cv::Rect2f box, bool global, bool lost = false) {
  TrackAnnotation out;
  out.index = 4;
  out.has_target = true;
  out.box = box;
  out.global = global;
  out.lost = lost;
  return out;
}

int count_color(const cv::Mat& bgr, const cv::Scalar& color) {
  cv::Mat mask;
  cv::inRange(bgr, color, color, mask);
  return cv::countNonZero(mask);
}

int count_color(const cv::Mat& bgr, const cv::Rect& area, const cv::Scalar& color) {
  return count_color(bgr(area & cv::Rect(cv::Point(), bgr.size())), color);
}

bool is_gray(const cv::Mat& bgr, int x, int y) {
  return bgr.at<cv::Vec3b>(y, x) == cv::Vec3b(kGray, kGray, kGray);
}

TEST(Annotate, GrayInputGivesABgrCopyOfTheSameSize) {
  const cv::Mat image = gray_image();
  const cv::Mat out = annotate_frame(image, TrackAnnotation{}, no_text());
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), image.size());
  EXPECT_EQ(count_color(out, cv::Scalar(kGray, kGray, kGray)), image.rows * image.cols);
  EXPECT_EQ(image.at<uchar>(0, 0), kGray) << "the input must not be drawn on";
}

TEST(Annotate, BgrInputIsCopiedNotDrawnOn) {
  const cv::Mat image(120, 160, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat before = image.clone();
  const cv::Mat out =
      annotate_frame(image, with_box({20, 20, 40, 40}, /*global=*/false), no_text());
  EXPECT_GT(count_color(out, AnnotateStyle{}.local_color), 0);
  EXPECT_EQ(cv::norm(image, before, cv::NORM_INF), 0.0);
}

TEST(Annotate, FlowIsBlendedInsideTheRegionOnly) {
  TrackAnnotation out;
  out.region = cv::Rect(30, 40, 50, 30);
  out.region_flow = cv::Mat(out.region.size(), CV_32FC2, cv::Scalar(3, -1));
  const AnnotateStyle style = no_text();
  const cv::Mat result = annotate_frame(gray_image(), out, style);

  cv::Mat expected;
  const cv::Mat color = flow::flow_to_color(out.region_flow, style.flow_max_magnitude);
  cv::addWeighted(cv::Mat(out.region.size(), CV_8UC3, cv::Scalar(kGray, kGray, kGray)),
                  1.0 - style.flow_alpha, color, style.flow_alpha, 0.0, expected);
  const cv::Vec3b inside = result.at<cv::Vec3b>(55, 55);
  EXPECT_EQ(inside, expected.at<cv::Vec3b>(15, 25));
  EXPECT_NE(inside, cv::Vec3b(kGray, kGray, kGray));
  EXPECT_TRUE(is_gray(result, 10, 10));
  EXPECT_TRUE(is_gray(result, 120, 100));
  // The outline is drawn on the region's border.
  EXPECT_EQ(result.at<cv::Vec3b>(40, 55), cv::Vec3b(255, 255, 255));
}

TEST(Annotate, WithoutFlowTheRegionIsOnlyOutlined) {
  TrackAnnotation out;
  out.region = cv::Rect(30, 40, 50, 30);
  const cv::Mat result = annotate_frame(gray_image(), out, no_text());
  EXPECT_TRUE(is_gray(result, 55, 55));
  EXPECT_GT(count_color(result, AnnotateStyle{}.region_color), 0);
}

TEST(Annotate, BoxColourFollowsTheMode) {
  const AnnotateStyle style = no_text();
  const cv::Rect2f box(40, 30, 50, 40);
  const cv::Mat local = annotate_frame(gray_image(), with_box(box, /*global=*/false), style);
  EXPECT_GT(count_color(local, style.local_color), 100);
  EXPECT_EQ(count_color(local, style.global_color), 0);
  EXPECT_EQ(count_color(local, style.lost_color), 0);

  const cv::Mat global = annotate_frame(gray_image(), with_box(box, /*global=*/true), style);
  EXPECT_GT(count_color(global, style.global_color), 100);
  EXPECT_EQ(count_color(global, style.local_color), 0);
}

TEST(Annotate, LostBoxIsDashedInTheLostColour) {
  const AnnotateStyle style = no_text();
  const cv::Mat lost =
      annotate_frame(gray_image(), with_box({40, 30, 50, 40}, /*global=*/false, true), style);
  EXPECT_EQ(count_color(lost, style.local_color), 0);
  // Along the top edge some pixels carry the colour and some are gaps.
  const int on_top_edge = count_color(lost, cv::Rect(40, 30, 50, 1), style.lost_color);
  EXPECT_GT(on_top_edge, 10);
  EXPECT_LT(on_top_edge, 45);
}

TEST(Annotate, VelocityArrowStartsAtTheBoxCentre) {
  AnnotateStyle style = no_text();
  TrackAnnotation out = with_box({40, 30, 40, 40}, /*global=*/false);
  out.velocity = {2, 0};  // 16 pixels long at the default scale
  const cv::Mat moving = annotate_frame(gray_image(), out, style);
  EXPECT_GT(count_color(moving, cv::Rect(60, 48, 18, 5), style.arrow_color), 10);
  EXPECT_EQ(count_color(moving, cv::Rect(40, 30, 19, 40), style.arrow_color), 0)
      << "nothing to the left of the centre";

  out.velocity = {0, 0};
  EXPECT_EQ(count_color(annotate_frame(gray_image(), out, style), style.arrow_color), 0);
}

TEST(Annotate, BoxesOutsideTheFrameAreClipped) {
  const AnnotateStyle style = no_text();
  // Top-left corner outside: only the right and bottom edges are visible, and nothing is drawn
  // along the frame's border where the box was cut.
  const cv::Mat corner =
      annotate_frame(gray_image(), with_box({-50, -50, 100, 100}, /*global=*/false), style);
  EXPECT_GT(count_color(corner, cv::Rect(45, 10, 8, 1), style.local_color), 0);
  EXPECT_EQ(count_color(corner, cv::Rect(0, 0, 3, 40), style.local_color), 0);
  EXPECT_EQ(count_color(corner, cv::Rect(0, 0, 40, 3), style.local_color), 0);

  for (const cv::Rect2f box : {cv::Rect2f(1000, 1000, 20, 20), cv::Rect2f(-500, 10, 20, 20),
                               cv::Rect2f(-1e30f, -1e30f, 2e30f, 2e30f),
                               cv::Rect2f(std::numeric_limits<float>::quiet_NaN(), 0, 10, 10),
                               cv::Rect2f(std::numeric_limits<float>::infinity(), 0, 10, 10)}) {
    TrackAnnotation out = with_box(box, /*global=*/false, box.x > 0);
    out.velocity = {1e20f, -1e20f};
    const cv::Mat result = annotate_frame(gray_image(), out, style);
    EXPECT_EQ(result.size(), cv::Size(160, 120));
    if (box.x == 1000 || box.x == -500) {
      EXPECT_EQ(count_color(result, cv::Scalar(kGray, kGray, kGray)), 160 * 120)
          << "box at " << box.x << " is out of sight";
    }
  }
}

TEST(Annotate, RegionsOutsideTheFrameAreClipped) {
  const AnnotateStyle style = no_text();
  for (const cv::Rect region :
       {cv::Rect(-20, 60, 300, 100), cv::Rect(500, 500, 10, 10), cv::Rect(-40, -40, 20, 20)}) {
    TrackAnnotation out;
    out.region = region;
    out.region_flow = cv::Mat(region.size(), CV_32FC2, cv::Scalar(1, 1));
    const cv::Mat result = annotate_frame(gray_image(), out, style);
    EXPECT_EQ(result.size(), cv::Size(160, 120));
    if (region.x == -20) {
      EXPECT_FALSE(is_gray(result, 80, 100)) << "the visible part is coloured";
      EXPECT_TRUE(is_gray(result, 80, 30));
      EXPECT_EQ(count_color(result, cv::Rect(0, 70, 2, 40), style.region_color), 0)
          << "no outline along the frame's border";
    } else {
      EXPECT_EQ(count_color(result, cv::Scalar(kGray, kGray, kGray)), 160 * 120);
    }
  }
}

TEST(Annotate, TextLineIsDrawnInTheTopLeftCorner) {
  TrackAnnotation out = with_box({40, 30, 50, 40}, /*global=*/false, true);
  const cv::Mat with = annotate_frame(gray_image(), out);
  const cv::Mat without = annotate_frame(gray_image(), out, no_text());
  const cv::Rect corner(0, 0, 60, 12);
  EXPECT_GT(cv::norm(with(corner), without(corner), cv::NORM_L1), 0.0);
  EXPECT_TRUE(is_gray(with, 150, 110));
}

TEST(Annotate, BadInputThrowsNamingTheValue) {
  EXPECT_NE(test::error_message([] {
              annotate_frame(cv::Mat(10, 10, CV_32FC1), TrackAnnotation{});
            }).find("32FC1"),
            std::string::npos);
  EXPECT_NE(test::error_message([] { annotate_frame(cv::Mat(), TrackAnnotation{}); }).find("empty"),
            std::string::npos);
  TrackAnnotation out;
  out.region = cv::Rect(0, 0, 20, 10);
  out.region_flow = cv::Mat(10, 10, CV_32FC2, cv::Scalar(0, 0));
  EXPECT_NE(test::error_message([&] { annotate_frame(gray_image(), out); }).find("20x10"),
            std::string::npos);
  AnnotateStyle style;
  style.flow_alpha = 1.5f;
  EXPECT_NE(test::error_message([&] {
              annotate_frame(gray_image(), TrackAnnotation{}, style);
            }).find("1.5"),
            std::string::npos);
  style = {};
  style.thickness = 0;
  EXPECT_NE(test::error_message([&] {
              annotate_frame(gray_image(), TrackAnnotation{}, style);
            }).find("thickness"),
            std::string::npos);
}

}  // namespace

namespace {

TEST(AnnotateObjects, EachIdInItsOwnColourWithLabelAndArrow) {
  std::set<std::tuple<double, double, double>> colours;
  for (long long id = 1; id <= 20; ++id) {
    const cv::Scalar c = report::id_color(id);
    colours.insert({c[0], c[1], c[2]});
    EXPECT_EQ(c, report::id_color(id));  // stable
  }
  EXPECT_EQ(colours.size(), 20u);

  report::ObjectsAnnotation frame;
  frame.index = 9;
  frame.objects = {{3, {10, 10, 30, 40}, {0.f, 0.f}, false, {}},
                   {7, {90, 50, 30, 40}, {3.f, 0.f}, false, {}},
                   {8, {60, 20, 20, 20}, {0.f, 0.f}, true, {}}};
  AnnotateStyle style = no_text();
  const cv::Mat out = report::annotate_objects(gray_image(), frame, style);
  ASSERT_EQ(out.type(), CV_8UC3);
  // Each box's outline in its id's colour, inside its own box's area only.
  EXPECT_GT(count_color(out, cv::Rect(8, 8, 34, 44), report::id_color(3)), 60);
  EXPECT_EQ(count_color(out, cv::Rect(88, 48, 34, 44), report::id_color(3)), 0);
  EXPECT_GT(count_color(out, cv::Rect(88, 48, 34, 44), report::id_color(7)), 60);
  // The lost one is dashed: fewer pixels than a full outline of its size.
  const int lost = count_color(out, cv::Rect(58, 18, 24, 24), report::id_color(8));
  EXPECT_GT(lost, 10);
  EXPECT_LT(lost, 2 * 2 * 80);
  // Velocity arrow of id 7 to the right of its centre, beyond its box.
  EXPECT_GT(count_color(out, cv::Rect(121, 66, 30, 8), report::id_color(7)), 5);
  // The label "#7" above its box (text pixels in its colour, anti-aliased, so look for any).
  const cv::Mat above = out(cv::Rect(90, 35, 30, 15));
  EXPECT_GT(cv::countNonZero(above.reshape(1) != kGray), 10);
  // The status line.
  const cv::Mat with_text = report::annotate_objects(gray_image(), frame);
  EXPECT_GT(cv::countNonZero(with_text(cv::Rect(0, 0, 100, 12)).reshape(1) != kGray), 50);
}

}  // namespace
