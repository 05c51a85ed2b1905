#include "flow/color_code.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.hpp"
#include "flow/metrics.hpp"

namespace roiflow::flow {
namespace {

constexpr int kWheelSize = 55;
using Rgb = std::array<int, 3>;

// Middlebury's makecolorwheel, integer divisions included, so our images match theirs.
constexpr std::array<Rgb, kWheelSize> make_wheel() {
  constexpr int kRy = 15, kYg = 6, kGc = 4, kCb = 11, kBm = 13, kMr = 6;
  static_assert(kRy + kYg + kGc + kCb + kBm + kMr == kWheelSize);
  std::array<Rgb, kWheelSize> wheel{};
  int k = 0;
  for (int i = 0; i < kRy; ++i)
    wheel[k++] = {255, 255 * i / kRy, 0};
  for (int i = 0; i < kYg; ++i)
    wheel[k++] = {255 - 255 * i / kYg, 255, 0};
  for (int i = 0; i < kGc; ++i)
    wheel[k++] = {0, 255, 255 * i / kGc};
  for (int i = 0; i < kCb; ++i)
    wheel[k++] = {0, 255 - 255 * i / kCb, 255};
  for (int i = 0; i < kBm; ++i)
    wheel[k++] = {255 * i / kBm, 0, 255};
  for (int i = 0; i < kMr; ++i)
    wheel[k++] = {255, 0, 255 - 255 * i / kMr};
  return wheel;
}

constexpr std::array<Rgb, kWheelSize> kWheel = make_wheel();

// The wheel in [0, 1], each entry exactly static_cast<float>(channel) / 255.f as computed per
// pixel before, looked up instead of divided.
using RgbF = std::array<float, 3>;
const std::array<RgbF, kWheelSize> kWheelF = [] {
  std::array<RgbF, kWheelSize> w{};
  for (int k = 0; k < kWheelSize; ++k) {
    for (int c = 0; c < 3; ++c)
      w[k][c] = static_cast<float>(kWheel[k][c]) / 255.f;
  }
  return w;
}();

// Middlebury's computeColor for a flow already divided by the normalising magnitude. Kept in
// float and truncating like the reference; writes OpenCV's B, G, R order.
void color_of(float fx, float fy, uchar* bgr) {
  const float rad = std::sqrt(fx * fx + fy * fy);
  const float a = std::atan2(-fy, -fx) / std::numbers::pi_v<float>;
  const float fk = (a + 1.f) / 2.f * (kWheelSize - 1);
  const int k0 = static_cast<int>(fk);
  const int k1 = (k0 + 1) % kWheelSize;
  const float f = fk - static_cast<float>(k0);
  for (int c = 0; c < 3; ++c) {
    const float col0 = kWheelF[k0][c];
    const float col1 = kWheelF[k1][c];
    float col = (1 - f) * col0 + f * col1;
    col = rad <= 1 ? 1 - rad * (1 - col) : col * 0.75f;
    bgr[2 - c] = static_cast<uchar>(255.f * col);
  }
}

void check_flow(const cv::Mat& flow, const char* what) {
  if (flow.empty() || flow.type() != CV_32FC2) {
    throw Error(std::string(what) + ": flow must be non-empty CV_32FC2, got " +
                std::to_string(flow.cols) + "x" + std::to_string(flow.rows) + " " +
                cv::typeToString(flow.type()));
  }
}

}  // namespace

float robust_max_magnitude(const cv::Mat& flow, double percentile) {
  check_flow(flow, "robust_max_magnitude");
  if (!(percentile > 0.0 && percentile <= 100.0)) {
    throw Error("robust_max_magnitude: percentile must be in (0, 100], got " +
                std::to_string(percentile));
  }
  // Squared magnitudes: the order is the same, and one square root is taken at the end.
  std::vector<float> squared;
  squared.reserve(flow.total());
  for (int y = 0; y < flow.rows; ++y) {
    const float* f = flow.ptr<float>(y);
    for (int x = 0; x < flow.cols; ++x) {
      if (is_known_flow(f[2 * x], f[2 * x + 1]))
        squared.push_back(f[2 * x] * f[2 * x] + f[2 * x + 1] * f[2 * x + 1]);
    }
  }
  if (squared.empty()) return 0.f;
  const auto n = static_cast<double>(squared.size());
  const std::size_t rank =
      static_cast<std::size_t>(std::clamp(std::ceil(percentile / 100.0 * n), 1.0, n) - 1.0);
  std::nth_element(squared.begin(), squared.begin() + static_cast<std::ptrdiff_t>(rank),
                   squared.end());
  return std::sqrt(squared[rank]);
}

float max_magnitude(const cv::Mat& flow) {
  return robust_max_magnitude(flow, 100.0);
}

cv::Mat flow_to_color(const cv::Mat& flow, float max_magnitude) {
  check_flow(flow, "flow_to_color");
  if (std::isinf(max_magnitude)) {
    throw Error("flow_to_color: max_magnitude must be finite, got " +
                std::to_string(max_magnitude));
  }
  float max_rad = max_magnitude;
  if (!(max_magnitude > 0)) {
    max_rad = robust_max_magnitude(flow);
    // An all-zero (or all-unknown) field would divide by zero; any scale gives white.
    if (!(max_rad > 0)) max_rad = 1;
  }

  cv::Mat bgr(flow.size(), CV_8UC3, cv::Scalar::all(0));
  for (int y = 0; y < flow.rows; ++y) {
    const float* f = flow.ptr<float>(y);
    uchar* out = bgr.ptr<uchar>(y);
    for (int x = 0; x < flow.cols; ++x) {
      if (is_known_flow(f[2 * x], f[2 * x + 1])) {
        color_of(f[2 * x] / max_rad, f[2 * x + 1] / max_rad, out + 3 * x);
      }
    }
  }
  return bgr;
}

cv::Mat color_wheel_legend(int size) {
  if (size < 3) throw Error("color_wheel_legend: size must be >= 3, got " + std::to_string(size));
  // White outside the circle: black already means "unknown flow" in the coding.
  cv::Mat legend(size, size, CV_8UC3, cv::Scalar::all(255));
  // Inside-the-circle test in exact integers (doubled offsets), so the legend is symmetric
  // whatever floating-point contraction the compiler applies.
  const int twice_centre = size - 1;
  const float centre = static_cast<float>(size - 1) / 2.f;
  for (int y = 0; y < size; ++y) {
    uchar* out = legend.ptr<uchar>(y);
    const int dy2 = 2 * y - twice_centre;
    const float fy = (static_cast<float>(y) - centre) / centre;
    for (int x = 0; x < size; ++x) {
      const int dx2 = 2 * x - twice_centre;
      if (dx2 * dx2 + dy2 * dy2 > twice_centre * twice_centre) continue;
      const float fx = (static_cast<float>(x) - centre) / centre;
      color_of(fx, fy, out + 3 * x);
    }
  }
  return legend;
}

cv::Mat draw_flow_vectors(const cv::Mat& image, const cv::Mat& flow, int step, float scale) {
  if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3)) {
    throw Error("draw_flow_vectors: image must be non-empty CV_8UC1 or CV_8UC3, got " +
                cv::typeToString(image.type()));
  }
  if (flow.type() != CV_32FC2 || flow.size() != image.size()) {
    throw Error("draw_flow_vectors: flow is " + std::to_string(flow.cols) + "x" +
                std::to_string(flow.rows) + " " + cv::typeToString(flow.type()) + ", image is " +
                std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                " (flow must be CV_32FC2, same size)");
  }
  if (step < 1) throw Error("draw_flow_vectors: step must be >= 1, got " + std::to_string(step));
  if (!std::isfinite(scale)) {
    throw Error("draw_flow_vectors: scale must be finite, got " + std::to_string(scale));
  }

  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  } else {
    out = image.clone();
  }
  // Longer arrows show nothing more and could overflow the int coordinates of the drawing.
  const double max_length = 2.0 * (image.rows + image.cols);
  const cv::Scalar arrow_color(0, 255, 0);
  for (int y = step / 2; y < flow.rows; y += step) {
    const float* f = flow.ptr<float>(y);
    for (int x = step / 2; x < flow.cols; x += step) {
      if (!is_known_flow(f[2 * x], f[2 * x + 1])) continue;
      double dx = double{f[2 * x]} * scale;
      double dy = double{f[2 * x + 1]} * scale;
      const double length = std::hypot(dx, dy);
      if (length > max_length) {
        dx *= max_length / length;
        dy *= max_length / length;
      }
      cv::arrowedLine(out, cv::Point(x, y), cv::Point(cvRound(x + dx), cvRound(y + dy)),
                      arrow_color, 1, cv::LINE_AA, 0, 0.3);
    }
  }
  return out;
}

}  // namespace roiflow::flow
