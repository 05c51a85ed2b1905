// KITTI optical-flow ground truth: 16-bit PNG files (KITTI 2012 and 2015 flow_occ/flow_noc).
//
//   using namespace roiflow;
//   cv::Mat truth = eval::read_kitti_flow("training/flow_occ/000042_10.png");
//   flow::FlowErrors e = flow::flow_errors(estimate, truth);      // invalid pixels not scored
//   eval::write_kitti_flow("out/000042_10.png", estimate);       // export for KITTI's devkit
//
// Each pixel holds three uint16: R = u * 64 + 32768, G = v * 64 + 32768, B = 1 where the flow
// is valid and 0 where it is not. Decoded flow is CV_32FC2 with invalid pixels set to the
// Middlebury "unknown" value (1e10, 1e10), so every roiflow function that skips unknown flow
// (flow_errors, flow_to_color, endpoint_error_image) skips them too. OpenCV holds colour in
// B, G, R order: R is channel 2. Malformed input throws roiflow::Error naming the file.
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
