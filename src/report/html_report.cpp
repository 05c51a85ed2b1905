#include "report/html_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "flow/color_code.hpp"
#include "flow/metrics.hpp"

namespace roiflow::report {
namespace {

constexpr int kColormap = cv::COLORMAP_INFERNO;
const cv::Vec3b kNotScored(128, 128, 128);

std::string base64(const std::vector<uchar>& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned n = (unsigned{bytes[i]} << 16) | (unsigned{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += kAlphabet[n & 63];
  }
  if (i + 1 == bytes.size()) {
    const unsigned n = unsigned{bytes[i]} << 16;
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const unsigned n = (unsigned{bytes[i]} << 16) | (unsigned{bytes[i + 1]} << 8);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += '=';
  }
  return out;
}

// ".png" or ".jpg"
std::string data_uri(const cv::Mat& image, const std::string& extension) {
  std::vector<uchar> bytes;
  const std::vector<int> options =
      extension == ".jpg" ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 90} : std::vector<int>{};
  if (!cv::imencode(extension, image, bytes, options)) {
    throw Error("cannot encode a report image as " + extension);
  }
  return "data:image/" + std::string(extension == ".jpg" ? "jpeg" : "png") + ";base64," +
         base64(bytes);
}

cv::Mat fit_width(const cv::Mat& image, int width) {
  if (image.cols <= width) return image;
  const int height = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(image.rows) * width / image.cols)));
  cv::Mat small;
  cv::resize(image, small, {width, height}, 0, 0, cv::INTER_AREA);
  return small;
}

// 1, 2, 5, 10, 20, 50, ... : the smallest one >= value (and >= 1 px).
double nice_scale(double value) {
  double scale = 1;
  for (int step = 0; scale < value && scale < 1e6; ++step)
    scale *= step % 3 == 1 ? 2.5 : 2;
  return scale;
}

// Heat map of the endpoint error over the scored pixels, grey elsewhere; the colour bar tops out
// at a round number above the 95th percentile, so a few wild pixels do not wash out the rest.
cv::Mat error_heat_map(const eval::EvalImages& images, double& scale) {
  const cv::Mat error = flow::endpoint_error_image(images.estimate, images.truth);
  std::vector<float> scored;
  for (int y = 0; y < error.rows; ++y) {
    const float* e = error.ptr<float>(y);
    const uchar* s = images.scored.ptr<uchar>(y);
    for (int x = 0; x < error.cols; ++x) {
      if (s[x]) scored.push_back(e[x]);
    }
  }
  double p95 = 0;
  if (!scored.empty()) {
    const auto nth = scored.begin() + static_cast<std::ptrdiff_t>(scored.size() * 95 / 100);
    std::nth_element(scored.begin(), nth, scored.end());
    p95 = *nth;
  }
  scale = nice_scale(p95);
  cv::Mat level;
  error.convertTo(level, CV_8U, 255.0 / scale);  // saturates above the scale
  cv::Mat heat;
  cv::applyColorMap(level, heat, kColormap);
  heat.setTo(kNotScored, images.scored == 0);
  return heat;
}

std::string colour_bar_uri() {
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i)
    ramp.at<uchar>(0, i) = static_cast<uchar>(i);
  cv::Mat bar;
  cv::applyColorMap(ramp, bar, kColormap);
  return data_uri(bar, ".png");
}

void check_images(const eval::EvalRow& row, const eval::EvalImages& images) {
  const cv::Size size = images.frame0.size();
  const bool ok = !images.frame0.empty() && images.frame0.type() == CV_8UC1 &&
                  images.frame1.type() == CV_8UC1 && images.frame1.size() == size &&
                  images.truth.type() == CV_32FC2 && images.truth.size() == size &&
                  images.estimate.type() == CV_32FC2 && images.estimate.size() == size &&
                  images.scored.type() == CV_8UC1 && images.scored.size() == size;
  if (!ok) {
    throw Error("report section '" + row.name +
                "': images must be two 8-bit frames, two CV_32FC2 flows and an 8-bit mask, "
                "all the same size");
  }
}

std::string cell(const std::string& text) {
  return "<td>" + text + "</td>";
}

bool any_extended(const std::vector<eval::EvalRow>& rows) {
  return std::any_of(rows.begin(), rows.end(),
                     [](const eval::EvalRow& r) { return r.noc.has_value() || r.kitti; });
}

std::string metrics_cells(const flow::FlowErrors& e, bool with_fl) {
  std::string out = cell(fixed(e.aae_deg, 3)) + cell(fixed(e.epe, 4)) + cell(fixed(e.r1, 2)) +
                    cell(fixed(e.r3, 2));
  if (with_fl) out += cell(fixed(e.fl, 2));
  return out + cell(std::to_string(e.pixels));
}

const char* kStyle = R"(
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
tr.mean td { font-weight: bold; background: #f3f3f3; }
.figures { display: flex; flex-wrap: wrap; gap: 0.8em; }
figure { margin: 0; }
figure img { display: block; max-width: 100%; image-rendering: auto; }
figcaption { font-size: 0.85em; color: #555; max-width: 480px; }
.bar { height: 10px; background-size: 100% 100%; }
.scale { display: flex; justify-content: space-between; font-size: 0.8em; color: #555; }
section { border-top: 2px solid #ddd; margin-top: 1.5em; padding-top: 0.5em; }
.legend { display: flex; align-items: center; gap: 1em; }
)";

}  // namespace

HtmlReport::HtmlReport(std::string title, std::string preset, const flow::LkParams& params,
                       int display_width)
    : title_(std::move(title)),
      preset_(std::move(preset)),
      params_(params),
      display_width_(display_width) {
  if (display_width < 16) {
    throw Error("report display width must be >= 16 px, got " + std::to_string(display_width));
  }
}

void HtmlReport::add(const eval::EvalRow& row, const eval::EvalImages& images) {
  check_images(row, images);
  Section section;
  section.row = row;
  const cv::Size size = images.frame0.size();
  // One maximum for both flows, so the same colour means the same motion in both.
  const double max_flow = flow::max_magnitude(images.truth);
  const float coding = max_flow > 0 ? static_cast<float>(max_flow) : 1.f;
  const std::string max_text = fixed(max_flow, 2) + " px";
  section.figures.push_back({"frame t (" + size_text(size) + ")",
                             data_uri(fit_width(images.frame0, display_width_), ".jpg")});
  section.figures.push_back(
      {"frame t+1", data_uri(fit_width(images.frame1, display_width_), ".jpg")});
  section.figures.push_back(
      {"ground truth (full saturation = " + max_text + "; black: unknown)",
       data_uri(fit_width(flow::flow_to_color(images.truth, coding), display_width_), ".jpg")});
  section.figures.push_back(
      {"estimate (same coding: full saturation = " + max_text + ")",
       data_uri(fit_width(flow::flow_to_color(images.estimate, coding), display_width_), ".jpg")});
  const cv::Mat heat = error_heat_map(images, section.error_scale);
  section.figures.push_back(
      {"endpoint error (grey: not scored)", data_uri(fit_width(heat, display_width_), ".jpg")});
  sections_.push_back(std::move(section));
}

std::string HtmlReport::html() const {
  std::vector<eval::EvalRow> rows;
  for (const Section& section : sections_)
    rows.push_back(section.row);
  const bool wide = any_extended(rows);
  const bool any_noc = std::any_of(rows.begin(), rows.end(),
                                   [](const eval::EvalRow& r) { return r.noc.has_value(); });

  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
      escape_markup(title_) + "</title>\n<style>" + kStyle + ".bar { background-image: url(" +
      colour_bar_uri() + "); }\n</style>\n</head>\n<body>\n<h1 id=\"top\">" +
      escape_markup(title_) + "</h1>\n";
  out += "<p>" + std::to_string(sections_.size()) + " pairs, Lucas&ndash;Kanade preset <b>" +
         escape_markup(preset_) + "</b>. Written by roiflow eval.</p>\n";

  out += "<h2>Lucas&ndash;Kanade parameters</h2>\n<table>\n";
  const nlohmann::ordered_json params = eval::params_json(params_);
  for (const auto& [key, value] : params.items()) {
    out += "<tr><td>" + escape_markup(key) + "</td><td>" +
           escape_markup(value.is_string() ? value.get<std::string>() : value.dump()) +
           "</td></tr>\n";
  }
  out += "</table>\n";

  out +=
      "<h2>Summary</h2>\n<table>\n<tr><th>sequence</th><th>AAE (deg)</th><th>EPE (px)</th>"
      "<th>R1 (%)</th><th>R3 (%)</th>";
  if (wide) out += "<th>Fl (%)</th>";
  if (any_noc) out += "<th>EPE noc (px)</th><th>Fl noc (%)</th>";
  out += "<th>ms</th></tr>\n";
  const auto summary_row = [&](const eval::EvalRow& row, const std::string& name_html,
                               const char* css) {
    std::string tr = std::string("<tr") + css + ">" + cell(name_html) +
                     cell(fixed(row.errors.aae_deg, 3)) + cell(fixed(row.errors.epe, 4)) +
                     cell(fixed(row.errors.r1, 2)) + cell(fixed(row.errors.r3, 2));
    if (wide) tr += cell(fixed(row.errors.fl, 2));
    if (any_noc) {
      tr += row.noc ? cell(fixed(row.noc->epe, 4)) + cell(fixed(row.noc->fl, 2))
                    : cell("-") + cell("-");
    }
    return tr + cell(fixed(row.ms, 2)) + "</tr>\n";
  };
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const eval::EvalRow& row = sections_[i].row;
    out += summary_row(
        row, "<a href=\"#pair-" + std::to_string(i + 1) + "\">" + escape_markup(row.name) + "</a>",
        "");
  }
  if (!rows.empty()) out += summary_row(eval::mean_row(rows), "mean", " class=\"mean\"");
  out += "</table>\n";
  out +=
      "<p>AAE: mean angular error; EPE: mean endpoint error; R1, R3: pixels with EPE over 1 "
      "and 3 px";
  if (wide) out += "; Fl: pixels with EPE over 3 px and over 5 % of the true motion (KITTI)";
  if (any_noc) out += "; noc: non-occluded pixels only";
  out += ".</p>\n";

  out += "<div class=\"legend\"><img alt=\"colour wheel\" width=\"101\" height=\"101\" src=\"" +
         data_uri(flow::color_wheel_legend(101), ".png") +
         "\"><p>Flow colour coding (Middlebury): hue gives the direction, saturation the "
         "magnitude; the rim of the wheel is the full-saturation magnitude given under each "
         "image.</p></div>\n";

  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Section& section = sections_[i];
    const eval::EvalRow& row = section.row;
    out += "<section id=\"pair-" + std::to_string(i + 1) + "\">\n<h2>" + escape_markup(row.name) +
           "</h2>\n<div class=\"figures\">\n";
    for (std::size_t f = 0; f < section.figures.size(); ++f) {
      const Figure& figure = section.figures[f];
      out += "<figure><img alt=\"" + escape_markup(row.name + ": " + figure.caption) + "\" src=\"" +
             figure.data_uri + "\">";
      if (f + 1 == section.figures.size()) {
        out += "<div class=\"bar\"></div><div class=\"scale\"><span>0</span><span>" +
               fixed(section.error_scale / 2, 1) + "</span><span>&ge; " +
               fixed(section.error_scale, 0) + " px</span></div>";
      }
      out += "<figcaption>" + escape_markup(figure.caption) + "</figcaption></figure>\n";
    }
    out +=
        "</div>\n<table>\n<tr><th>scored</th><th>AAE (deg)</th><th>EPE (px)</th>"
        "<th>R1 (%)</th><th>R3 (%)</th>" +
        std::string(wide ? "<th>Fl (%)</th>" : "") + "<th>pixels</th></tr>\n";
    out += "<tr>" + cell("all scored") + metrics_cells(row.errors, wide) + "</tr>\n";
    if (row.noc) out += "<tr>" + cell("non-occluded") + metrics_cells(*row.noc, wide) + "</tr>\n";
    out += "</table>\n<p>dense flow: " + fixed(row.ms, 2) +
           " ms. <a href=\"#top\">back to the summary</a></p>\n</section>\n";
  }
  out += "</body>\n</html>\n";
  return out;
}

void HtmlReport::write(const std::string& path) const {
  write_text_atomically(path, html());
}

}  // namespace roiflow::report
