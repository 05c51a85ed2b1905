#include "eval/kitti_flow.hpp"

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "flow/metrics.hpp"

namespace roiflow::eval {
namespace {

constexpr double kScale = 64.0;
constexpr double kOffset = 32768.0;

std::string describe(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows) + " " + cv::typeToString(m.type());
}

}  // namespace

cv::Mat decode_kitti_flow(const cv::Mat& png) {
  if (png.empty() || png.type() != CV_16UC3) {
    throw Error("KITTI flow must be a 16-bit 3-channel image, got " + describe(png));
  }
  cv::Mat flow(png.size(), CV_32FC2);
  for (int y = 0; y < png.rows; ++y) {
    const ushort* in = png.ptr<ushort>(y);
    float* out = flow.ptr<float>(y);
    for (int x = 0; x < png.cols; ++x) {
      const ushort* bgr = in + 3 * x;
      if (bgr[0] == 0) {
        out[2 * x] = out[2 * x + 1] = kKittiInvalidFlow;
        continue;
      }
      out[2 * x] = static_cast<float>((bgr[2] - kOffset) / kScale);
      out[2 * x + 1] = static_cast<float>((bgr[1] - kOffset) / kScale);
    }
  }
  return flow;
}

cv::Mat read_kitti_flow(const std::string& path) {
  std::error_code ec;
  // Checked first because cv::imread would add a warning of its own on stderr.
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("cannot read KITTI flow '" + path + "': no such file");
  }
  const cv::Mat png = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (png.empty()) throw Error("cannot decode KITTI flow '" + path + "'");
  try {
    return decode_kitti_flow(png);
  } catch (const Error& e) {
    throw Error("'" + path + "': " + e.what());
  }
}

cv::Mat encode_kitti_flow(const cv::Mat& flow, bool out_of_range_invalid) {
  if (flow.empty() || flow.type() != CV_32FC2) {
    throw Error("encode_kitti_flow: flow must be non-empty CV_32FC2, got " + describe(flow));
  }
  cv::Mat png(flow.size(), CV_16UC3);
  for (int y = 0; y < flow.rows; ++y) {
    const float* in = flow.ptr<float>(y);
    ushort* out = png.ptr<ushort>(y);
    for (int x = 0; x < flow.cols; ++x) {
      ushort* bgr = out + 3 * x;
      const float u = in[2 * x];
      const float v = in[2 * x + 1];
      if (!flow::is_known_flow(u, v)) {
        bgr[0] = bgr[1] = bgr[2] = 0;
        continue;
      }
      // The range check is on the rounded value, so everything that passes fits a uint16.
      const double ru = std::round(u * kScale) + kOffset;
      const double rv = std::round(v * kScale) + kOffset;
      if (ru < 0 || ru > 65535 || rv < 0 || rv > 65535) {
        if (out_of_range_invalid) {
          bgr[0] = bgr[1] = bgr[2] = 0;
          continue;
        }
        throw Error("encode_kitti_flow: flow (" + number_text(u) + ", " + number_text(v) +
                    ") at (" + std::to_string(x) + "," + std::to_string(y) +
                    ") is outside the KITTI range [-512, 511.984375]");
      }
      bgr[0] = 1;
      bgr[1] = static_cast<ushort>(rv);
      bgr[2] = static_cast<ushort>(ru);
    }
  }
  return png;
}

void write_kitti_flow(const std::string& path, const cv::Mat& flow) {
  const cv::Mat png = encode_kitti_flow(flow);
  write_atomically(path, "KITTI flow ",
                   [&](const std::string& partial) { return cv::imwrite(partial, png); });
}

}  // namespace roiflow::eval
