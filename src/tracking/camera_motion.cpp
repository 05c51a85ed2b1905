#include "tracking/camera_motion.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::tracking {

std::optional<cv::Point2f> camera_shift(const cv::Mat& previous, const cv::Mat& current,
                                        const cv::Rect2f& exclude,
                                        const CameraShiftParams& params) {
  if (previous.type() != CV_8UC1 || current.type() != CV_8UC1 || previous.empty() ||
      previous.size() != current.size()) {
    throw Error("camera shift: two 8-bit gray frames of one size expected");
  }
  if (params.work_width < 16 || !(params.min_response >= 0 && params.min_response <= 1)) {
    throw Error("camera shift: work_width must be >= 16 and min_response in [0, 1], got " +
                number_text(params.work_width) + " and " + number_text(params.min_response));
  }
  const int factor = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(previous.cols) / params.work_width)));
  const cv::Size work(previous.cols / factor, previous.rows / factor);
  if (work.width < 8 || work.height < 8) return std::nullopt;
  cv::Mat a, b;
  if (factor > 1) {
    cv::resize(previous, a, work, 0, 0, cv::INTER_AREA);
    cv::resize(current, b, work, 0, 0, cv::INTER_AREA);
  } else {
    a = previous;
    b = current;
  }
  cv::Scalar mean, deviation;
  cv::meanStdDev(a, mean, deviation);
  if (!(deviation[0] >= 1.0)) return std::nullopt;  // a flat picture shows no motion
  a.convertTo(a, CV_32F);
  b.convertTo(b, CV_32F);
  if (exclude.width > 0 && exclude.height > 0) {
    // The object's pixels in `previous` fade to the mean (a soft edge: a hard one would be a
    // pattern of its own), so that only the rest of the picture can correlate with `current`.
    const double f = 1.0 / factor;
    const double gx = 0.25 * exclude.width, gy = 0.25 * exclude.height;
    cv::Mat keep(work, CV_32F, cv::Scalar(1.f));
    const cv::Rect hole =
        cv::Rect(cv::Point(static_cast<int>(std::floor((exclude.x - gx) * f)),
                           static_cast<int>(std::floor((exclude.y - gy) * f))),
                 cv::Point(static_cast<int>(std::ceil((exclude.br().x + gx) * f)),
                           static_cast<int>(std::ceil((exclude.br().y + gy) * f)))) &
        cv::Rect(cv::Point(), work);
    if (!hole.empty()) {
      keep(hole).setTo(0.f);
      cv::GaussianBlur(keep, keep, cv::Size(), 2.0);
      a = static_cast<float>(mean[0]) + (a - static_cast<float>(mean[0])).mul(keep);
    }
  }
  cv::Mat window;
  cv::createHanningWindow(window, work, CV_32F);
  double response = 0;
  const cv::Point2d s = cv::phaseCorrelate(a, b, window, &response);
  if (!(response >= params.min_response) || !std::isfinite(s.x) || !std::isfinite(s.y)) {
    return std::nullopt;
  }
  // The shrunk frame's pixel i covers full-resolution pixels [i f, (i + 1) f).
  return cv::Point2f(static_cast<float>(s.x * factor), static_cast<float>(s.y * factor));
}

}  // namespace roiflow::tracking
