// MOTChallenge files and multi-object tracking scores: CLEAR-MOT (MOTA, MOTP, FP, FN, ID
// switches) and IDF1, at IoU >= 0.5, as py-motmetrics and TrackEval compute them.
//
//   using namespace roiflow;
//   const auto gt = eval::read_mot("PETS09-S2L1/gt/gt.txt", "ground truth");
//   const auto pred = eval::read_mot("mot.txt", "tracker output");
//   const eval::MotScore s = eval::score_mot(pred, gt);   // s.mota, s.idf1, s.id_switches...
//   eval::write_mot("out/mot.txt", pred);                 // frame,id,x,y,w,h,conf,-1,-1,-1
//
// Files: one box per line, `frame,id,x,y,w,h[,conf[,...]]` (commas; a line without a comma
// may separate its values by spaces or tabs). Frames count from 1, ids are integers >= 0, boxes
// are top-left corner and size in pixels. The columns after the box depend on the file:
//  - 7 columns: conf. 10 columns: conf and three more values (tracker output's -1,-1,-1 or
//    MOT15 ground truth's world coordinates), not used.
//  - 8 or 9 columns: conf, class, visibility (MOT16/17/20 ground truth).
// Ground truth, as TrackEval's MotChallenge2DBox preprocessing (the official MOTChallenge kit):
//  - Boxes with conf 0 ("zero marked") are not scored. A tracker box over one is a false
//    positive, as in TrackEval and py-motmetrics.
//  - Where a class column is present, only class 1 (pedestrian) is scored, and in each frame a
//    tracker box matched (IoU >= 0.5, maximum-IoU assignment over every ground-truth box) to a
//    distractor (class 2 person on vehicle, 7 static person, 8 distractor, 12 reflection) is
//    removed before scoring. Other classes are neither scored nor used to remove boxes.
//    Visibility is read and checked (0..1) but, as TrackEval's default, does not filter.
//  - A tracker's conf does not filter (py-motmetrics and TrackEval score every tracker box).
// CLEAR-MOT (Bernardin & Stiefelhagen 2008), per frame in frame order, as py-motmetrics'
// MOTAccumulator: first each ground-truth object keeps the hypothesis it was last matched to
// (in any earlier frame) when that hypothesis is present and still overlaps it at IoU >= 0.5;
// the rest are matched by optimal assignment (most pairs at IoU >= 0.5, then least total
// 1 - IoU). A match whose object was last matched to another hypothesis is an ID switch.
// Unmatched objects are FN, unmatched hypotheses FP. MOTA = 1 - (FN + FP + IDSW) / GT boxes.
// MOTP is the mean IoU of the matches (TrackEval's MOTP; py-motmetrics reports 1 - this).
// IDF1 (Ristani et al. 2016): the one-to-one pairing of tracker ids to ground-truth ids that
// maximises the number of frames where paired boxes overlap at IoU >= 0.5 (IDTP);
// IDF1 = 2 IDTP / (GT boxes + tracker boxes).
// Where py-motmetrics and TrackEval differ (TrackEval keeps a correspondence from the previous
// frame only, py-motmetrics from the last frame it held), this follows py-motmetrics; both
// agree whenever an object is matched in consecutive frames.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace roiflow::eval {

struct MotBox {
  int frame = 1;
  int id = 0;
  cv::Rect2d box;
  double conf = 1;
  int object_class = 0;    // 0: the file has no class column
  double visibility = -1;  // -1: the file has no visibility column
};

// Reads a MOTChallenge file; `what` names it in errors ("ground truth", "tracker output").
// Throws roiflow::Error as `path:line: what was wrong` for a missing file, fewer than 6 or more
// than 10 columns, a value that is not a number, a frame < 1, an id < 0 or not an integer, a
// negative size, a class outside 1..13, a visibility outside 0..1, or an id twice in a frame.
// Blank lines are skipped. Rows are returned sorted by (frame, id).
std::vector<MotBox> read_mot(const std::string& path, const std::string& what);
// The same from text in memory; `name` stands for the path in error messages.
std::vector<MotBox> parse_mot(std::string_view text, const std::string& name);

// `frame,id,x,y,w,h,conf,-1,-1,-1` lines, sorted by (frame, id), boxes with 2 decimals.
std::string format_mot(std::vector<MotBox> boxes);
// format_mot written atomically (roiflow::Error when it cannot be written).
void write_mot(const std::string& path, const std::vector<MotBox>& boxes);

struct MotScore {
  double mota = 0;
  double motp = 0;  // mean IoU of the matches; 0 without matches
  double idf1 = 0;
  double idp = 0;  // IDTP / tracker boxes
  double idr = 0;  // IDTP / ground-truth boxes
  long long id_switches = 0;
  long long fp = 0;
  long long fn = 0;
  long long matches = 0;
  long long gt_boxes = 0;    // ground-truth boxes scored
  long long pred_boxes = 0;  // tracker boxes scored
  long long frames = 0;      // frames holding a scored ground-truth or tracker box
  long long objects = 0;     // ground-truth ids scored
  long long tracks = 0;      // tracker ids scored
};

// Throws roiflow::Error when the ground truth has no box to score.
MotScore score_mot(const std::vector<MotBox>& pred, const std::vector<MotBox>& gt);

// Intersection over union of two x,y,w,h boxes (continuous areas, as TrackEval and
// py-motmetrics); 0 when either is empty.
double mot_iou(const cv::Rect2d& a, const cv::Rect2d& b);

}  // namespace roiflow::eval
