// How the whole picture moved between two frames (the camera's pan and shake, as a translation):
// phase correlation of both frames shrunk to about `work_width` pixels wide (a Hann window
// against the edges' wrap-around), the peak refined to sub-pixel and scaled back to full
// resolution, the tracked object's pixels left out. The tracker uses it to predict where a
// target goes when the camera jumps (docs/BENCHMARK.md).
//
//   #include "tracking/camera_motion.hpp"
//   const std::optional<cv::Point2f> g =
//       roiflow::tracking::camera_shift(frame_t, frame_t1, cv::Rect2f(70, 51, 107, 87));
//   if (g) std::cout << "the picture moved by " << *g << " px\n";
#pragma once

#include <opencv2/core.hpp>
#include <optional>

namespace roiflow::tracking {

struct CameraShiftParams {
  int work_width = 160;        // frames are shrunk by the whole factor nearest this width, >= 16
  double min_response = 0.05;  // weaker phase-correlation peaks are no measurement, [0, 1]
};

// `previous` and `current`: 8-bit gray, one size (else roiflow::Error). `exclude`: a box of
// `previous` whose pixels take no part (the tracked object, which moves unlike the picture; empty
// = none). The shift, pixels of the full-resolution frame (a point at p in `previous` is at
// p + shift in `current`), or nothing when the peak is too weak or the frames are too small to
// tell.
std::optional<cv::Point2f> camera_shift(const cv::Mat& previous, const cv::Mat& current,
                                        const cv::Rect2f& exclude = {},
                                        const CameraShiftParams& params = {});

}  // namespace roiflow::tracking
