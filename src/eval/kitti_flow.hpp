// KITTI optical-flow ground truth (2012 and 2015, flow_occ/flow_noc): 16-bit PNGs whose pixels
// hold R = u * 64 + 32768, G = v * 64 + 32768 and B = 1 where the flow is valid. Decoded flow is
// CV_32FC2 with invalid pixels set to the Middlebury "unknown" value, so every function that
// skips unknown flow (flow_errors, flow_to_color) skips them. Malformed input throws
// roiflow::Error naming the file.
//
//   const cv::Mat flow(frame_t.size(), CV_32FC2, cv::Scalar(2.f, 0.f));
//   roiflow::eval::write_kitti_flow("000042_10.png", flow);  // for KITTI's devkit
//   const cv::Mat truth = roiflow::eval::read_kitti_flow("000042_10.png");
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace roiflow::eval {

// The value decode_kitti_flow gives invalid pixels (unknown for flow::is_known_flow).
inline constexpr float kKittiInvalidFlow = 1e10f;

// `png` as cv::imread(path, cv::IMREAD_UNCHANGED) returns it: CV_16UC3, B G R. Throws
// roiflow::Error for any other type or an empty image.
cv::Mat decode_kitti_flow(const cv::Mat& png);
// Reads and decodes; throws roiflow::Error naming `path` when it is missing, unreadable or not
// a 16-bit 3-channel PNG.
cv::Mat read_kitti_flow(const std::string& path);

// CV_16UC3 (B G R) for cv::imwrite; unknown flow is written invalid (all three zero), known flow
// is rounded to 1/64 px. Throws roiflow::Error when `flow` is not CV_32FC2 or a known value is
// outside [-512, 512 - 1/64] (the encoding cannot hold it; clamping would be a silent lie),
// unless `out_of_range_invalid`: such a vector is then written invalid, as unknown flow is (a
// video's per-pair output keeps going past one wild vector).
cv::Mat encode_kitti_flow(const cv::Mat& flow, bool out_of_range_invalid = false);
// Encodes and writes `path` (.png) atomically.
void write_kitti_flow(const std::string& path, const cv::Mat& flow);

}  // namespace roiflow::eval
