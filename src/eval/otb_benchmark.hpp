// OTB benchmark data: the sequences of an OTB-layout folder, the score of one tracker's run over
// one sequence (AUC, precision@20, mean IoU, frames/s, how many of its wrong frames it reported
// lost), per-tracker means, and the tables (Markdown, CSV) that `roiflow benchmark` writes.
//
//   using namespace roiflow;
//   const std::vector<eval::OtbSequence> seqs = eval::find_otb_sequences("data/tracking");
//   eval::TrackerRun run;                       // what a tracker reported on seqs[0]
//   run.boxes = {seqs[0].truth[0]};             // one box and one lost flag per frame
//   run.lost = {false};
//   run.cpu_s = 0.001;                          // CPU time of its calls
//   std::vector<eval::BenchmarkRow> rows = {eval::score_run(seqs[0].name, "mine", seqs[0].truth,
//   run)}; const std::vector<eval::BenchmarkRow> means = eval::tracker_means(rows, {"mine"});
//   std::cout << eval::format_benchmark_markdown(rows, means);
//
// A sequence is a folder holding `groundtruth_rect.txt` (OTB's x,y,w,h or TinyTLP's 6 columns,
// read by read_ground_truth) and its frames in `img/`. The scores are otb_score.hpp's: frames
// whose target is absent are not scored. The lost share is over the scored frames whose box has
// IoU 0 with the target: the share of them that the tracker itself reported lost (a tracker that
// knows when it is wrong scores 1). A tracker's mean row averages the per-sequence AUC,
// precision@20 and mean IoU (each sequence weighs the same, as in OTB), its curves likewise, and
// pools frames, time and IoU-0 frames: its frames/s is all frames over all CPU time.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "eval/otb_score.hpp"
#include "eval/track_log.hpp"

namespace roiflow::eval {

struct OtbSequence {
  std::string name;               // the folder's name
  std::string dir;                // the folder (frames in dir/img)
  std::vector<cv::Rect2f> truth;  // one box per frame; NaN = target absent
};

// The sequences of `dir`: its sub-folders holding groundtruth_rect.txt, sorted by name, or `dir`
// itself when it holds one. Sub-folders without that file are not sequences; their names go to
// `skipped` when given. Throws roiflow::Error when `dir` is not a directory, when it holds no
// sequence, or when a ground-truth file cannot be read (read_ground_truth's message) or marks the
// target absent in its first frame (a tracker starts from that box).
std::vector<OtbSequence> find_otb_sequences(const std::string& dir,
                                            std::vector<std::string>* skipped = nullptr);

// What one tracker reported over one sequence: box i and lost flag i belong to frame i.
struct TrackerRun {
  std::vector<cv::Rect2f> boxes;
  std::vector<bool> lost;
  double cpu_s = 0;        // CPU time of the tracker's calls over these frames
  std::vector<double> ms;  // optional: the CPU time of each frame's call, milliseconds
};

// The run as a track log (track_log.hpp's CSV, header included): frame i + 1, box i, lost i,
// ms i (0 without ms), no velocity, mode local. `roiflow score` reads it back (its boxes rounded to
// 2 decimals, so its scores can differ from score_run's in the fourth decimal).
std::string track_log_csv(const TrackerRun& run);

struct BenchmarkRow {
  std::string sequence;  // "mean" for a tracker's mean row
  std::string tracker;
  long long frames = 0;  // frames run (a mean row: over all sequences)
  long long scored = 0;  // frames scored (target present)
  double auc = 0;
  double precision20 = 0;
  double mean_iou = 0;
  double fps = 0;  // frames / cpu_s
  double cpu_s = 0;
  long long lost = 0;           // frames reported lost
  long long zero_iou = 0;       // scored frames with IoU 0
  long long zero_iou_lost = 0;  // ... of which reported lost
  OtbCurves curves;
  int sequences = 1;  // sequences behind the row

  // zero_iou_lost / zero_iou; NaN when no frame had IoU 0.
  double lost_share() const;
};

// Throws roiflow::Error when the run's boxes and lost flags differ in number, or as score().
BenchmarkRow score_run(const std::string& sequence, const std::string& tracker,
                       const std::vector<cv::Rect2f>& truth, const TrackerRun& run);

// One mean row per tracker named in `trackers` (in that order) over its rows in `rows`. Throws
// roiflow::Error when a tracker has no row or when the trackers' rows name different sequences.
std::vector<BenchmarkRow> tracker_means(const std::vector<BenchmarkRow>& rows,
                                        const std::vector<std::string>& trackers);

// The per-sequence AUC table (a column per tracker, the means last), then every figure of every
// row, the means last.
std::string format_benchmark_markdown(const std::vector<BenchmarkRow>& rows,
                                      const std::vector<BenchmarkRow>& means);
// Header `sequence,tracker,frames,scored,auc,precision20,mean_iou,fps,cpu_s,lost,zero_iou,
// zero_iou_lost,lost_share`, one line per row, then the mean rows (sequence "mean"); lost_share
// is empty when no frame had IoU 0.
std::string format_benchmark_csv(const std::vector<BenchmarkRow>& rows,
                                 const std::vector<BenchmarkRow>& means);

}  // namespace roiflow::eval
