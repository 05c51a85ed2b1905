// OpenCV's MOG2 background model (cv::BackgroundSubtractorMOG2) in bands of rows: each band of
// at least 32 rows has a model of its own. MOG2 models each pixel alone, so the mask is the one a
// single model over the whole frame gives. The bands are independent work: given an executor
// that runs bodies at once (concurrency() > 1), the frame is cut into up to one band per thread
// and the bands learn in parallel through it (the MOT graph passes its TbbExecutor, which lifts
// the serial background node that bounds tracking on many cores). Without one, or with a serial
// one, there is a single band: plain MOG2, with one model's memory.
//
//   roiflow::tracking::BandedMog2Params params;  // history 500, variance threshold 16, shadows
//   roiflow::tracking::BandedMog2 model(params);
//   cv::Mat mask;  // CV_8U: 255 foreground, 127 shadow, 0 background
//   model.apply(frame_t, mask);         // MOG2's own learning rate
//   model.apply(frame_t1, mask, 0.01);  // or a given one
//   const roiflow::SerialExecutor serial;     // one band; given a parallel executor (the
//   model.apply(frame_t1, mask, -1, &serial);  // pipeline's TbbExecutor) the bands run at once
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/video/background_segm.hpp>
#include <optional>
#include <vector>

#include "core/executor.hpp"

namespace roiflow::tracking {

struct BandedMog2Params {
  int history = 500;                       // MOG2 history, frames
  double var_threshold = 16;               // MOG2 variance threshold
  bool shadows = true;                     // label shadows (127)
  std::optional<double> shadow_threshold;  // unset: OpenCV's default
  std::optional<double> background_ratio;  // unset: OpenCV's default
};

class BandedMog2 {
 public:
  explicit BandedMog2(const BandedMog2Params& params) : params_(params) {}
  // The frame's mask (CV_8U, frame-sized); the first frame sets the size the model keeps, and
  // the bands (from `executor`'s concurrency then). `executor` (may be null) runs the bands.
  void apply(const cv::Mat& image, cv::Mat& mask, double learning_rate = -1,
             const Executor* executor = nullptr);

 private:
  BandedMog2Params params_;
  std::vector<cv::Ptr<cv::BackgroundSubtractorMOG2>> models_;
  std::vector<cv::Range> bands_;
};

}  // namespace roiflow::tracking
