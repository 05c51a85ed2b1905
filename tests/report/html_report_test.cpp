#include "report/html_report.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/atomic_write.hpp"
#include "eval/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::report {
namespace {

namespace fs = std::filesystem;
using eval::EvalImages;
using eval::EvalRow;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

// The src="data:..." URIs of every <img>, in order.
std::vector<std::string> image_uris(const std::string& html) {
  std::vector<std::string> uris;
  const std::string marker = "<img ";
  for (std::size_t at = html.find(marker); at != std::string::npos;
       at = html.find(marker, at + 1)) {
    const std::size_t src = html.find("src=\"", at) + 5;
    uris.push_back(html.substr(src, html.find('"', src) - src));
  }
  return uris;
}

std::vector<uchar> base64_decode(const std::string& text) {
  std::vector<uchar> out;
  unsigned buffer = 0;
  int bits = 0;
  for (char c : text) {
    int value;
    if (c >= 'A' && c <= 'Z') {
      value = c - 'A';
    } else if (c >= 'a' && c <= 'z') {
      value = c - 'a' + 26;
    } else if (c >= '0' && c <= '9') {
      value = c - '0' + 52;
    } else if (c == '+') {
      value = 62;
    } else if (c == '/') {
      value = 63;
    } else {
      break;  // '=' padding
    }
    buffer = (buffer << 6) | static_cast<unsigned>(value);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uchar>((buffer >> bits) & 0xFF));
    }
  }
  return out;
}

cv::Mat decode_uri(const std::string& uri) {
  const std::size_t comma = uri.find(',');
  EXPECT_EQ(uri.rfind("data:image/", 0), 0u);
  EXPECT_NE(uri.find(";base64,"), std::string::npos);
  return cv::imdecode(base64_decode(uri.substr(comma + 1)), cv::IMREAD_COLOR);
}

// A pair's images as evaluate_pair gives them: frames, truth, an estimate off by (1, 0)
// everywhere, and a scored mask with the left quarter not scored.
EvalImages images_of(cv::Size size) {
  const eval::Scene scene = eval::make_translation(size, {2.f, 1.f});
  EvalImages images;
  images.frame0 = scene.frame0;
  images.frame1 = scene.frame1;
  images.truth = scene.flow;
  images.estimate = scene.flow + cv::Scalar(1, 0);
  images.scored = cv::Mat(size, CV_8UC1, cv::Scalar(255));
  images.scored.colRange(0, size.width / 4).setTo(0);
  return images;
}

EvalRow row_named(const std::string& name, double epe) {
  EvalRow row;
  row.name = name;
  row.errors.epe = epe;
  row.errors.pixels = 1000;
  row.ms = 3;
  return row;
}

using HtmlReportTest = test::TempDirTest;

TEST_F(HtmlReportTest, OneSectionPerPairWithFiveImagesAndTheLegend) {
  HtmlReport report("roiflow eval <tree>", "paper", flow::LkParams::paper());
  const std::vector<std::string> names = {"alley_1/frame_0001", "cave_2/frame_0007", "000042"};
  for (std::size_t i = 0; i < names.size(); ++i)
    report.add(row_named(names[i], 0.5 + static_cast<double>(i)), images_of({96, 64}));
  ASSERT_EQ(report.size(), 3u);
  const std::string html = report.html();

  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("</html>"), std::string::npos);
  EXPECT_NE(html.find("roiflow eval &lt;tree&gt;"), std::string::npos);  // escaped
  EXPECT_EQ(html.find("<tree>"), std::string::npos);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string anchor = "pair-" + std::to_string(i + 1);
    EXPECT_NE(html.find("href=\"#" + anchor + "\">" + names[i] + "</a>"), std::string::npos)
        << names[i];
    EXPECT_NE(html.find("<section id=\"" + anchor + "\">\n<h2>" + names[i] + "</h2>"),
              std::string::npos)
        << names[i];
  }
  EXPECT_EQ(count(html, "<section "), 3u);
  EXPECT_EQ(count(html, "</section>"), 3u);
  // Self-contained: every image inline, nothing fetched.
  const std::vector<std::string> uris = image_uris(html);
  EXPECT_EQ(uris.size(), 3u * 5 + 1);
  for (const std::string& uri : uris)
    EXPECT_EQ(uri.rfind("data:image/", 0), 0u);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  // The mean row and the LK parameters.
  EXPECT_NE(html.find("<tr class=\"mean\"><td>mean</td><td>0.000</td><td>1.5000</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>patch</td><td>10</td>"), std::string::npos);
  EXPECT_NE(html.find("<b>paper</b>"), std::string::npos);
}

TEST_F(HtmlReportTest, ImagesDecodeDownscaledWithTheErrorScaleAndNotScoredGrey) {
  HtmlReport report("r", "paper", flow::LkParams::paper(), 120);
  EvalImages images = images_of({240, 160});
  report.add(row_named("wide", 1.0), images);
  HtmlReport small("r", "paper", flow::LkParams::paper(), 480);
  small.add(row_named("small", 1.0), images);

  const std::vector<std::string> uris = image_uris(report.html());
  ASSERT_EQ(uris.size(), 6u);
  for (std::size_t i = 1; i < uris.size(); ++i) {
    const cv::Mat image = decode_uri(uris[i]);
    ASSERT_FALSE(image.empty()) << i;
    EXPECT_EQ(image.size(), cv::Size(120, 80)) << i;  // 240x160 downscaled to 120 wide
  }
  const cv::Mat heat = decode_uri(image_uris(small.html())[5]);
  ASSERT_EQ(heat.size(), cv::Size(240, 160));  // not upscaled
  // Not scored (left quarter): grey. Scored: EPE 1 everywhere, on a colour bar up to 1 px: the
  // top of the colour map (inferno's pale yellow), far from grey.
  const cv::Vec3b grey = heat.at<cv::Vec3b>(80, 20);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(grey[c], 128, 6);
  const cv::Vec3b hot = heat.at<cv::Vec3b>(80, 200);
  EXPECT_GT(hot[2], 200);  // red channel high
  EXPECT_LT(hot[0], 200);  // blue lower: yellow, not grey
  EXPECT_NE(small.html().find("<span>&ge; 1 px</span>"), std::string::npos);
}

TEST_F(HtmlReportTest, BothFlowsUseTheGroundTruthsMaximum) {
  HtmlReport report("r", "paper", flow::LkParams::paper());
  EvalImages images = images_of({96, 64});
  images.estimate = images.truth * 2;  // twice as long: must look more saturated, not the same
  report.add(row_named("p", 1.0), images);
  const std::string html = report.html();
  // |(2, 1)| = 2.236 for both captions.
  EXPECT_NE(html.find("<figcaption>ground truth (full saturation = 2.24 px;"), std::string::npos);
  EXPECT_NE(html.find("<figcaption>estimate (same coding: full saturation = 2.24 px)"),
            std::string::npos);
  const std::vector<std::string> uris = image_uris(html);
  const cv::Mat truth = decode_uri(uris[3]);
  const cv::Mat estimate = decode_uri(uris[4]);
  // Same coding: the truth sits on the wheel's rim (full colour), the estimate beyond it, where
  // the Middlebury coding darkens colours to 75 %. Own maxima would make both look the same.
  const cv::Scalar truth_mean = cv::mean(truth);
  const cv::Scalar estimate_mean = cv::mean(estimate);
  EXPECT_LT(estimate_mean[0] + estimate_mean[1] + estimate_mean[2],
            0.85 * (truth_mean[0] + truth_mean[1] + truth_mean[2]));
}

TEST_F(HtmlReportTest, NocAndFlColumnsOnlyWhenThereAreSuch) {
  HtmlReport plain("r", "paper", flow::LkParams::paper());
  plain.add(row_named("Venus", 0.5), images_of({64, 48}));
  EXPECT_EQ(plain.html().find("Fl (%)"), std::string::npos);
  EXPECT_EQ(plain.html().find("non-occluded"), std::string::npos);

  HtmlReport kitti("r", "paper", flow::LkParams::paper());
  EvalRow row = row_named("000000", 2.0);
  row.kitti = true;
  row.errors.fl = 12.5;
  row.noc = row.errors;
  row.noc->epe = 1.25;
  kitti.add(row, images_of({64, 48}));
  const std::string html = kitti.html();
  EXPECT_NE(html.find("<th>Fl (%)</th>"), std::string::npos);
  EXPECT_NE(html.find("<th>EPE noc (px)</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>non-occluded</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>1.2500</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>12.50</td>"), std::string::npos);
}

TEST_F(HtmlReportTest, WritesAtomicallyAndRejectsBadImages) {
  HtmlReport report("r", "paper", flow::LkParams::paper());
  report.add(row_named("p", 1.0), images_of({64, 48}));
  report.write(path("report.html"));
  std::ifstream in(path("report.html"), std::ios::binary);
  const std::string written{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(written, report.html());
  EXPECT_FALSE(fs::exists(partial_path(path("report.html"))));
  EXPECT_THROW(report.write(path("no/such/dir/report.html")), Error);

  EvalImages bad = images_of({64, 48});
  bad.scored = cv::Mat(10, 10, CV_8UC1);
  EXPECT_NE(test::error_message([&] { report.add(row_named("broken", 1), bad); }).find("broken"),
            std::string::npos);
  bad = images_of({64, 48});
  bad.estimate = cv::Mat();
  EXPECT_THROW(report.add(row_named("empty", 1), bad), Error);
  EXPECT_EQ(report.size(), 1u);
  EXPECT_THROW(HtmlReport("r", "paper", flow::LkParams::paper(), 4), Error);
}

}  // namespace
}  // namespace roiflow::report
