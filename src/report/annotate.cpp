#include "report/annotate.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "flow/color_code.hpp"

namespace roiflow::report {
namespace {

constexpr int kDash = 8;
constexpr int kGap = 5;

void check_style(const AnnotateStyle& s) {
  if (!(s.flow_alpha >= 0.f && s.flow_alpha <= 1.f)) {
    throw Error("annotate: flow_alpha must be in 0..1, got " + std::to_string(s.flow_alpha));
  }
  if (!(s.arrow_scale >= 0.f && std::isfinite(s.arrow_scale))) {
    throw Error("annotate: arrow_scale must be finite and >= 0, got " +
                std::to_string(s.arrow_scale));
  }
  if (s.thickness < 1 || s.thickness > 16) {
    throw Error("annotate: thickness must be in 1..16, got " + std::to_string(s.thickness));
  }
}

cv::Mat bgr_copy(const cv::Mat& image) {
  if (image.empty()) throw Error("annotate: empty image");
  cv::Mat bgr;
  if (image.type() == CV_8UC1) {
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  } else if (image.type() == CV_8UC3) {
    bgr = image.clone();
  } else {
    throw Error("annotate: image must be 8-bit gray or BGR, got " + cv::typeToString(image.type()));
  }
  return bgr;
}

// The box clamped to the frame grown by `margin` on every side, so that the edges of a box
// that sticks out are drawn outside the canvas (invisible) rather than along its border, and
// coordinates far outside (or huge) never reach OpenCV's integer drawing. nullopt when no part
// of the box is visible or it is not a finite box.
std::optional<cv::Rect> drawable(const cv::Rect2f& box, cv::Size frame, int margin) {
  const double x0 = box.x, y0 = box.y, x1 = x0 + box.width, y1 = y0 + box.height;
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1) ||
      box.width < 0 || box.height < 0) {
    return std::nullopt;
  }
  if (x1 < 0 || y1 < 0 || x0 > frame.width || y0 > frame.height) return std::nullopt;
  auto clamp = [margin](double v, int extent) {
    return static_cast<int>(std::lround(std::clamp(v, -margin * 1.0, extent + margin * 1.0)));
  };
  const int left = clamp(x0, frame.width), top = clamp(y0, frame.height);
  return cv::Rect(cv::Point(left, top), cv::Point(clamp(x1, frame.width), clamp(y1, frame.height)));
}

void dashed_line(cv::Mat& canvas, cv::Point from, cv::Point to, const cv::Scalar& color,
                 int thickness) {
  const cv::Point2d step = to - from;
  const double length = std::hypot(step.x, step.y);
  if (length == 0) return;
  for (double s = 0; s < length; s += kDash + kGap) {
    const double e = std::min(s + kDash, length);
    const cv::Point2d a = cv::Point2d(from) + step * (s / length);
    const cv::Point2d b = cv::Point2d(from) + step * (e / length);
    cv::line(canvas, cv::Point(cvRound(a.x), cvRound(a.y)), cv::Point(cvRound(b.x), cvRound(b.y)),
             color, thickness, cv::LINE_8);
  }
}

void draw_box(cv::Mat& canvas, const cv::Rect& r, const cv::Scalar& color, int thickness,
              bool dashed) {
  if (!dashed) {
    cv::rectangle(canvas, r, color, thickness, cv::LINE_8);
    return;
  }
  const cv::Point tl = r.tl(), tr(r.x + r.width, r.y), br = r.br(), bl(r.x, r.y + r.height);
  dashed_line(canvas, tl, tr, color, thickness);
  dashed_line(canvas, tr, br, color, thickness);
  dashed_line(canvas, br, bl, color, thickness);
  dashed_line(canvas, bl, tl, color, thickness);
}

void blend_flow(cv::Mat& canvas, const TrackAnnotation& out, const AnnotateStyle& style) {
  if (out.region_flow.empty()) return;
  if (out.region_flow.type() != CV_32FC2 || out.region_flow.size() != out.region.size()) {
    throw Error("annotate: region_flow must be CV_32FC2 of the region's size " +
                std::to_string(out.region.width) + "x" + std::to_string(out.region.height) +
                ", got " + cv::typeToString(out.region_flow.type()) + " " +
                std::to_string(out.region_flow.cols) + "x" + std::to_string(out.region_flow.rows));
  }
  const cv::Rect visible = out.region & cv::Rect(cv::Point(), canvas.size());
  if (visible.empty()) return;
  // Coloured over the whole region, so that the saturation scale does not depend on clipping.
  const cv::Mat color = flow::flow_to_color(out.region_flow, style.flow_max_magnitude);
  cv::Mat target = canvas(visible);
  cv::addWeighted(target, 1.0 - style.flow_alpha, color(visible - out.region.tl()),
                  style.flow_alpha, 0.0, target);
}

void draw_velocity(cv::Mat& canvas, const TrackAnnotation& out, const AnnotateStyle& style) {
  const cv::Point2d centre(out.box.x + out.box.width / 2.0, out.box.y + out.box.height / 2.0);
  cv::Point2d arrow = cv::Point2d(out.velocity) * static_cast<double>(style.arrow_scale);
  if (!std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(arrow.x) ||
      !std::isfinite(arrow.y)) {
    return;
  }
  if (!cv::Rect2d(0, 0, canvas.cols, canvas.rows).contains(centre)) return;
  double length = std::hypot(arrow.x, arrow.y);
  if (length < 1) return;
  // Longer than the diagonal says nothing more and would overflow int coordinates.
  const double diagonal = std::hypot(canvas.cols, canvas.rows);
  if (length > diagonal) {
    arrow *= diagonal / length;
    length = diagonal;
  }
  const cv::Point from(cvRound(centre.x), cvRound(centre.y));
  const cv::Point to(cvRound(centre.x + arrow.x), cvRound(centre.y + arrow.y));
  const double tip = std::min(0.3, 10.0 / length);  // a readable head on long arrows too
  cv::arrowedLine(canvas, from, to, style.arrow_color, style.thickness, cv::LINE_8, 0, tip);
}

void draw_text(cv::Mat& canvas, const TrackAnnotation& out) {
  std::string text =
      "frame " + std::to_string(out.index + 1) + "  " + (out.global ? "global" : "local");
  if (!out.has_target) {
    text += "  no target";
  } else if (out.lost) {
    text += "  lost";
  }
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double scale = std::max(0.4, canvas.rows / 960.0);
  const int thickness = 1;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font, scale, thickness, &baseline);
  const int pad = 4;
  // A dark backing keeps the text readable over bright frames and flow colours.
  cv::rectangle(canvas, cv::Rect(0, 0, size.width + 2 * pad, size.height + baseline + 2 * pad),
                cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(canvas, text, cv::Point(pad, pad + size.height), font, scale,
              cv::Scalar(255, 255, 255), thickness, cv::LINE_AA);
}

}  // namespace

cv::Mat annotate_frame(const cv::Mat& image, const TrackAnnotation& out,
                       const AnnotateStyle& style) {
  check_style(style);
  cv::Mat canvas = bgr_copy(image);
  blend_flow(canvas, out, style);
  const int margin = style.thickness + 2;
  if (auto region = drawable(cv::Rect2f(out.region), canvas.size(), margin);
      region && !out.region.empty()) {
    cv::rectangle(canvas, *region, style.region_color, style.thickness, cv::LINE_8);
  }
  if (out.has_target) {
    if (auto box = drawable(out.box, canvas.size(), margin)) {
      const cv::Scalar& color = out.lost     ? style.lost_color
                                : out.global ? style.global_color
                                             : style.local_color;
      draw_box(canvas, *box, color, style.thickness, out.lost);
    }
    draw_velocity(canvas, out, style);
  }
  if (style.text) draw_text(canvas, out);
  return canvas;
}

cv::Scalar id_color(long long id) {
  // Hues spread by the golden angle: neighbouring ids far apart on the colour wheel.
  const double hue = std::fmod(static_cast<double>(id < 0 ? -id : id) * 137.508, 360.0);
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue / 2.0, 230, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

cv::Mat annotate_objects(const cv::Mat& image, const ObjectsAnnotation& frame,
                         const AnnotateStyle& style) {
  check_style(style);
  cv::Mat canvas = bgr_copy(image);
  const int margin = style.thickness + 2;
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double scale = std::max(0.4, canvas.rows / 1200.0);
  for (const ObjectAnnotation& o : frame.objects) {
    const cv::Scalar color = id_color(o.id);
    if (auto region = drawable(cv::Rect2f(o.region), canvas.size(), margin);
        region && !o.region.empty()) {
      cv::rectangle(canvas, *region, color * 0.6, 1, cv::LINE_8);
    }
    const auto box = drawable(o.box, canvas.size(), margin);
    if (!box) continue;
    draw_box(canvas, *box, color, style.thickness, o.lost);
    TrackAnnotation arrow;
    arrow.box = o.box;
    arrow.velocity = o.velocity;
    AnnotateStyle arrow_style = style;
    arrow_style.arrow_color = color;
    draw_velocity(canvas, arrow, arrow_style);
    std::string label = "#";  // appended, not "#" + ...: GCC 12 warns falsely (-Wrestrict)
    label += std::to_string(o.id);
    int baseline = 0;
    const cv::Size size = cv::getTextSize(label, font, scale, 1, &baseline);
    const cv::Point at(std::clamp(box->x, 0, std::max(0, canvas.cols - size.width)),
                       std::clamp(box->y - 3, size.height, std::max(size.height, canvas.rows - 1)));
    cv::rectangle(canvas, cv::Rect(at.x, at.y - size.height - 1, size.width, size.height + 3),
                  cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(canvas, label, at, font, scale, color, 1, cv::LINE_AA);
  }
  if (style.text) {
    long long shown = 0;
    for (const ObjectAnnotation& o : frame.objects)
      if (!o.lost) ++shown;
    std::string text = "frame " + std::to_string(frame.index + 1) + "  objects " +
                       std::to_string(shown) + "  born " + std::to_string(frame.born) + "  ended " +
                       std::to_string(frame.ended) + (frame.global ? "  global" : "");
    const double tscale = std::max(0.4, canvas.rows / 960.0);
    int baseline = 0;
    const cv::Size size = cv::getTextSize(text, font, tscale, 1, &baseline);
    const int pad = 4;
    cv::rectangle(canvas, cv::Rect(0, 0, size.width + 2 * pad, size.height + baseline + 2 * pad),
                  cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(canvas, text, cv::Point(pad, pad + size.height), font, tscale,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace roiflow::report
