#include "flow/pyramid.hpp"

#include <opencv2/imgproc.hpp>
#include <string>

#include "flow/error.hpp"

namespace roiflow::flow {

int effective_levels(cv::Size size, int requested) {
  if (requested < 1 || requested > kMaxLevels) {
    throw Error("levels must be in 1.." + std::to_string(kMaxLevels) + ", got " +
                std::to_string(requested));
  }
  int levels = 1;
  while (levels < requested) {
    const cv::Size next = level_size(size, levels);
    if (std::min(next.width, next.height) < kMinLevelSide) break;
    ++levels;
  }
  return levels;
}

cv::Size level_size(cv::Size size, int level) {
  for (int l = 0; l < level; ++l)
    size = cv::Size((size.width + 1) / 2, (size.height + 1) / 2);
  return size;
}

namespace {

void to_unit_float(const cv::Mat& image, cv::Mat& out) {
  switch (image.type()) {
    case CV_8UC1:
      image.convertTo(out, CV_32F, 1.0 / 255.0);
      break;
    case CV_8UC3: {
      cv::Mat gray;
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      gray.convertTo(out, CV_32F, 1.0 / 255.0);
      break;
    }
    case CV_16UC1:
      image.convertTo(out, CV_32F, 1.0 / 65535.0);
      break;
    case CV_32FC1:
      image.copyTo(out);
      break;
    default:
      throw Error("image type must be 8-bit gray, 8-bit BGR, 16-bit gray or float gray, got " +
                  cv::typeToString(image.type()));
  }
}

}  // namespace

void build_pyramid(const cv::Mat& image, int levels, double sigma, Pyramid& out) {
  if (image.empty()) throw Error("image is empty");
  if (!(sigma >= 0.0 && sigma <= 20.0)) {
    throw Error("smoothing sigma must be in [0, 20], got " + std::to_string(sigma));
  }
  const int n = effective_levels(image.size(), levels);
  out.levels.resize(n);
  cv::Mat& base = out.levels[0];
  to_unit_float(image, base);
  if (sigma > 0.0) cv::GaussianBlur(base, base, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  for (int l = 1; l < n; ++l)
    cv::pyrDown(out.levels[l - 1], out.levels[l]);
}

Pyramid build_pyramid(const cv::Mat& image, int levels, double sigma) {
  Pyramid pyr;
  build_pyramid(image, levels, sigma, pyr);
  return pyr;
}

}  // namespace roiflow::flow
