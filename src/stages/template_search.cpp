#include "stages/template_search.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "flow/error.hpp"

namespace roiflow::stages {
namespace {

// Offset in (-0.5, 0.5) of a parabola's vertex through three equally spaced samples.
float parabola_peak(float left, float centre, float right) {
  const float denom = left - 2.f * centre + right;
  if (!(denom < 0.f)) return 0.f;
  return std::clamp(0.5f * (left - right) / denom, -0.5f, 0.5f);
}

cv::Mat resized(const cv::Mat& src, cv::Size size) {
  if (size == src.size()) return src;
  cv::Mat out;
  const bool shrink = size.area() < src.size().area();
  cv::resize(src, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

// Best full-resolution match of `templ` (already scaled) in `region` of `image`.
TemplateMatch match_one(const cv::Mat& image, const cv::Mat& templ, const cv::Rect& region) {
  TemplateMatch best;
  if (region.width < templ.cols || region.height < templ.rows) return best;
  cv::Mat response;
  cv::matchTemplate(image(region), templ, response, cv::TM_CCOEFF_NORMED);
  double max_value = 0;
  cv::Point at;
  cv::minMaxLoc(response, nullptr, &max_value, nullptr, &at);
  if (!std::isfinite(max_value)) return best;
  float dx = 0.f, dy = 0.f;
  if (at.x > 0 && at.x + 1 < response.cols) {
    dx = parabola_peak(response.at<float>(at.y, at.x - 1), response.at<float>(at.y, at.x),
                       response.at<float>(at.y, at.x + 1));
  }
  if (at.y > 0 && at.y + 1 < response.rows) {
    dy = parabola_peak(response.at<float>(at.y - 1, at.x), response.at<float>(at.y, at.x),
                       response.at<float>(at.y + 1, at.x));
  }
  best.score = max_value;
  best.box =
      cv::Rect2f(static_cast<float>(region.x + at.x) + dx, static_cast<float>(region.y + at.y) + dy,
                 static_cast<float>(templ.cols), static_cast<float>(templ.rows));
  return best;
}

}  // namespace

TemplateMatch match_template(const cv::Mat& image, const cv::Mat& templ, const cv::Rect& search,
                             const TemplateSearchParams& params) {
  if (image.empty() || templ.empty()) throw Error("template search: empty image or template");
  if (image.channels() != 1 || templ.channels() != 1) {
    throw Error("template search: image and template must be single-channel");
  }
  if (image.depth() != templ.depth() || (image.depth() != CV_8U && image.depth() != CV_32F)) {
    throw Error("template search: image and template must both be 8-bit or both float, got " +
                cv::typeToString(image.type()) + " and " + cv::typeToString(templ.type()));
  }
  if (params.scales.empty()) throw Error("template search: no scales given");
  for (double s : params.scales) {
    if (!(s > 0.0) || !std::isfinite(s)) {
      throw Error("template search: scales must be positive, got " + std::to_string(s));
    }
  }
  const cv::Rect region = search & cv::Rect(0, 0, image.cols, image.rows);
  TemplateMatch best;
  if (region.empty()) return best;

  for (double scale : params.scales) {
    const cv::Size size(std::max(1, static_cast<int>(std::lround(templ.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(templ.rows * scale))));
    if (size.width > region.width || size.height > region.height) continue;
    const cv::Mat scaled = resized(templ, size);
    const int side = std::min(size.width, size.height);
    TemplateMatch m;
    if (params.coarse_side > 0 && side > params.coarse_side) {
      // Coarse pass over the whole region, then a window of a few coarse pixels at full size.
      const double f = static_cast<double>(params.coarse_side) / side;
      const cv::Size coarse_templ(std::max(1, static_cast<int>(std::lround(size.width * f))),
                                  std::max(1, static_cast<int>(std::lround(size.height * f))));
      const cv::Size coarse_region(std::max(1, static_cast<int>(std::lround(region.width * f))),
                                   std::max(1, static_cast<int>(std::lround(region.height * f))));
      if (coarse_templ.width > coarse_region.width || coarse_templ.height > coarse_region.height) {
        continue;
      }
      const cv::Mat small_image = resized(image(region), coarse_region);
      const TemplateMatch coarse = match_one(small_image, resized(scaled, coarse_templ),
                                             cv::Rect(cv::Point(), coarse_region));
      if (coarse.score <= -1) continue;
      const int pad = static_cast<int>(std::ceil(2.0 / f)) + 1;
      const cv::Rect window(region.x + static_cast<int>(std::lround(coarse.box.x / f)) - pad,
                            region.y + static_cast<int>(std::lround(coarse.box.y / f)) - pad,
                            size.width + 2 * pad, size.height + 2 * pad);
      m = match_one(image, scaled, window & region);
    } else {
      m = match_one(image, scaled, region);
    }
    if (m.score > best.score) {
      best = m;
      best.scale = scale;
    }
  }
  return best;
}

}  // namespace roiflow::stages
