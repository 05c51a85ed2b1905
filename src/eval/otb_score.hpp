// OTB one-pass evaluation (OPE) of a track against ground-truth boxes, as the OTB benchmark's
// MATLAB code computes it (success AUC over 21 IoU thresholds, precision@20 px, mean IoU), with
// the departures docs/SCORING.md lists (absent-target frames left out, the shorter length
// scored); the ground-truth reader, the track's boxes, the curves of the plots and the text
// `roiflow score` prints.
//
//   const std::vector<cv::Rect2f> truth =
//       roiflow::eval::parse_ground_truth("10,10,40,30\n12,11,40,30\n", "memory");
//   const std::vector<cv::Rect2f> track = {{10, 10, 40, 30}, {13, 11, 40, 30}};
//   const roiflow::eval::OtbScore s = roiflow::eval::score(track, truth);
//   std::cout << roiflow::eval::score_table(s, track.size(), truth.size());  // AUC, precision...
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "eval/track_log.hpp"

namespace roiflow::eval {

struct OtbScore {
  double auc = 0;          // success AUC, 0..20/21
  double precision20 = 0;  // share of frames with centre error <= 20 px
  double mean_iou = 0;
  long long frames = 0;  // frames scored
};

// One box `x,y,w,h` per line, the values separated by commas, tabs or spaces (OTB files mix
// them, and end lines with CRLF). Blank lines are skipped. A line of four NaN marks the target
// absent and is kept, as NaN, so that line numbers stay frame numbers. A file whose first line
// holds 6 values is TinyTLP's `frame,x,y,w,h,absent`: frames must run 1, 2, 3, ..., and a line
// with absent = 1 marks the target absent (kept as NaN); absent is 0 or 1, and every line has 6.
// Missing files, another number of values, text that is not a number, infinities, values beyond the
// float range, a partly NaN line and a negative size throw roiflow::Error as `path:line: what was
// wrong`.
std::vector<cv::Rect2f> read_ground_truth(const std::string& path);
// The same from a file's text held in memory; `name` stands for the path in error messages.
std::vector<cv::Rect2f> parse_ground_truth(std::string_view text, const std::string& name);

// A box typed by a user, "x,y,w,h" (commas and/or spaces), with a finite positive size. Throws
// roiflow::Error ("expected x,y,w,h, got '1,2,3'") otherwise.
cv::Rect2f parse_box(const std::string& text);

// The boxes of a track log, box i being frame i + 1. Throws roiflow::Error naming the record
// when frames are not numbered 1, 2, 3, ... in order (the pairing with ground truth would be
// wrong).
std::vector<cv::Rect2f> track_boxes(const std::vector<TrackRecord>& records);
// track_boxes of the track-log CSV at `path` (read_track_csv); errors name the file.
std::vector<cv::Rect2f> read_track_boxes(const std::string& path);

// Throws roiflow::Error, naming both lengths, when no frame is left to score.
OtbScore score(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth);

// What `roiflow score` prints: AUC, precision@20 and mean IoU to 4 decimals, and the frames
// scored with both lengths (a shorter track, --max-frames, scores only its prefix).
std::string score_table(const OtbScore& s, std::size_t track_boxes, std::size_t truth_boxes);
// The curves of OTB's success and precision plots for one track, over the frames score()
// scores: success[k] is the share of frames with IoU > k / 20 (k = 0..20; their mean is the AUC),
// precision[t] the share with a centre error <= t px (t = 0..50; precision[20] is
// precision@20). Throws like score(). Averaging the curves of several sequences gives the plots
// of a whole benchmark (OTB's perfPlot.m averages per sequence too).
constexpr int kSuccessThresholds = 21;
constexpr int kPrecisionThresholds = 51;
struct OtbCurves {
  std::vector<double> success;    // kSuccessThresholds values
  std::vector<double> precision;  // kPrecisionThresholds values
  long long frames = 0;           // frames scored
};
OtbCurves otb_curves(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth);
// The area under a success curve: the mean of its values (0 for an empty curve).
double curve_auc(const std::vector<double>& success);

// 0 when either box is empty (zero or negative size) or not finite.
double iou(const cv::Rect2f& a, const cv::Rect2f& b);
// Distance between the box centres in pixels; infinity when either box is not finite.
double center_error(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace roiflow::eval
