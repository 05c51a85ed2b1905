// OTB one-pass evaluation (OPE) of a track against ground-truth boxes.
//
//   using namespace roiflow;
//   const auto truth = eval::read_ground_truth("Car4/groundtruth_rect.txt");
//   const auto track = eval::track_boxes(eval::read_track_csv("car4.csv"));
//   const eval::OtbScore s = eval::score(track, truth);   // s.auc, s.precision20, ...
//
// The metrics follow the OTB benchmark's MATLAB code (Wu, Lim, Yang, CVPR 2013 and TPAMI 2015;
// calcSeqErrRobust.m, calcRectInt.m, perfPlot.m), which pysot and got10k reproduce:
//  - IoU of the axis-aligned boxes. OTB's inclusive pixel bounds (right = x + w - 1, overlap
//    width = min(right) - max(left) + 1) give exactly the continuous intersection used here.
//  - Success AUC: the mean, over the 21 thresholds t = 0, 0.05, ..., 1, of the share of frames
//    with IoU > t (strictly, as OTB's `errCoverage > thresholdSetOverlap`). No IoU exceeds 1,
//    so a perfect track scores 20/21 = 0.952, as it does in OTB.
//  - Precision@20: the share of frames whose centre error is <= 20 px (`errCenter <=`). OTB's
//    centre x + (w - 1) / 2 and the x + w / 2 used here differ by the same 0.5 px for both
//    boxes, so the distance is the same.
//  - Mean IoU over the scored frames.
// Where this departs from OTB's code, on purpose:
//  - Ground-truth frames that mark the target absent (NaN, or a width or height that is not
//    positive, e.g. an all-zero line) are left out of every metric and of `frames`. OTB instead
//    counts them in the denominator as IoU -1 (a miss at every threshold) and centre error -1 (a
//    hit at every threshold), and also treats a present target at x = 0 or y = 0 as absent.
//  - The track's first box is scored as given. OTB overwrites it with the ground truth; a
//    tracker started with `--init` from that box logs it anyway.
//  - Frame i is compared with frame i over the shorter of the two lengths: a track cut short
//    (`--max-frames`) scores its prefix; extra boxes on either side are ignored (OTB drops a
//    longer result's tail too). `frames` says how many frames were scored; callers that want
//    the full sequence compare it with the ground truth's length.
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

// The boxes of a track log, box i being frame i + 1. Throws roiflow::Error naming the record
// when frames are not numbered 1, 2, 3, ... in order (the pairing with ground truth would be
// wrong).
std::vector<cv::Rect2f> track_boxes(const std::vector<TrackRecord>& records);

// Throws roiflow::Error, naming both lengths, when no frame is left to score.
OtbScore score(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth);

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
