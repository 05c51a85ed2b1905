// MotionDetector: the global treatment for every moving object of a fixed camera — a background
// model (the background refresh), its foreground mask, and the moving objects found in it.
//
//   using namespace roiflow::tracking;
//   MotionDetector detector;                              // MOG2 on a half-size copy at 768x576
//   for (const cv::Mat& picture : {bgr, bgr}) {           // the frames of a fixed camera
//     Foreground fg = detector.observe(picture);          // background refresh: serial, in order
//     std::vector<Detection> objects = detect_objects(fg, detector.params());  // stateless
//     if (fg.moving_share({10, 20, 30, 60}) > 0.5) objects.clear();  // moving share of a box
//   }
//
// observe() updates OpenCV's MOG2 with a frame shrunk by the whole factor that brings it nearest
// `work_width` (shadows are detected and count as background) and returns the frame's
// foreground mask with its integral image; a part of it that has not changed for
// `ghost_frames` frames (a ghost, or an object that stopped) is absorbed into the background at
// once, until its gray level changes. With `start_frames`, in the first frames (the model learnt
// its first frame, moving objects included, as background) motion decides instead: moving is
// foreground, still is background. With `start_motion` the motion is the frames' dense flow (the
// paper's global treatment: a fixed camera's background does not move), and a part of the
// foreground whose pixels move in distinct ways is one object per motion (two vehicles crossing);
// else it is each neighbourhood's change against a few frames back.
// detect_objects() is the global treatment proper and
// keeps no state, so a pipeline runs it beside the next frame's refresh: morphology (an opening
// removes speckle, a closing joins the parts of one object), connected components, the boxes of
// those of at least `min_area` full-resolution pixels, and a merge of nested or duplicate boxes
// (a box mostly inside another joins it: one object seen as a body and a detached part).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"
#include "tracking/global_detector.hpp"

namespace roiflow::tracking {

struct MotionDetectorParams {
  int history = 500;              // frames the background model remembers (MOG2 history), >= 2
  double var_threshold = 16;      // MOG2's squared Mahalanobis distance to call a pixel moving, > 0
  int change_frames = 4;          // Foreground::changed compares with this many frames back, >= 1
  double change_level = 25;       // gray levels (model resolution) a changed pixel differs by, > 0
  int ghost_frames = 8;           // a foreground pixel that has not changed for this many frames
                                  // in a row is a ghost (or a stopped object) and is absorbed into
                                  // the background at once, until its gray level changes; 0 = never
  int start_frames = 30;          // scene start: the model learns its first frame as background,
                                  // objects moving in it included; in these first frames a pixel
                                  // whose neighbourhood moves is foreground inside a foreground
                                  // part (never across the valley between two), and foreground
                                  // whose neighbourhood provably stands still is background such
                                  // an object uncovered (absorbed like a ghost); 0 = none. About a
                                  // second of video: by then the model (learning at 1/frames
                                  // early on) weighs its first frame under 1/30
  double start_motion = 0.5;      // scene start with the frames' flow (observe's `back`):
                                  // a pixel whose motion differs from the frame's median motion
                                  // (a fixed camera's: about zero) by at least this many pixels
                                  // a frame moves and is foreground, one within half of it
                                  // stands still and is background (a ghost is absorbed at
                                  // once), and a part of the foreground whose moving pixels
                                  // hold several distinct motions splits into one object per
                                  // motion; detections start with the second frame. 0 = off
  double start_reach = 5;         // full-resolution pixels a moving object's flow reaches
                                  // beyond its edge (half the LK window): the moving pixels are
                                  // eroded by it, >= 0
  double start_texture = 1.0;     // the flow decides only where its window is at least this
                                  // many times as textured (smallest structure eigenvalue) as
                                  // the frame's median window; elsewhere LK holds the coarser
                                  // levels' motion, which spreads an object's motion over a
                                  // uniform background around it, >= 0 (0 = everywhere)
  double background_ratio = 0.5;  // MOG2's background: its heaviest modes that together hold this
                                  // share of the recent frames, (0, 1]. OpenCV's 0.9 takes for
                                  // background any colour seen 10% of the time: the body of a
                                  // slow or long vehicle, and early on (when the model learns
                                  // fast) the back of every moving object
  int work_width = 384;           // the model works on frames shrunk by the whole factor that
                                  // brings them nearest this width; 0 = full resolution
  bool shadows = true;            // MOG2 labels shadows, which then count as background
  double shadow_threshold = 0.5;  // MOG2's tau: a pixel darker than the background by a ratio in
                                  // [tau, 1) with its colour is a shadow, (0, 1)
  double shadow_enclosed = 0.7;   // a shadow part whose outline lies next to the foreground for
                                  // at least this share of its length is the body of an object
                                  // (a grey car on asphalt), not its cast shadow, which touches
                                  // its object on one side: it is foreground (shadow_parts.hpp).
                                  // [0, 1], 0 = never
  int warmup = 5;                 // detect_objects finds nothing in the first frames observed
  int open = 3;                   // opening kernel side at work resolution (0 = none)
  int close = 7;                  // closing kernel width at work resolution (0 = none)
  int close_h = 0;                // closing kernel height at work resolution (0 = close)
  double min_area = 400;          // smallest object, full-resolution pixels of its box, ...
  double min_model_area = 100;    // ... or this many pixels at the model's resolution where
                                  // that is less (a frame the model sees at full size, e.g.
                                  // 320x240: a far car is a real object there, and the opening
                                  // already removed the speckle); 0 = min_area alone
  double merge_overlap = 0.6;     // boxes whose intersection holds this share of the smaller one
                                  // merge, (0, 1]
  double split_valley = 0.7;      // a blob splits at a column where its count of moving pixels
                                  // falls under this share of the peaks on both sides (objects
                                  // side by side), each part at least `split_width` of its
                                  // height wide; 0 = never, [0, 1)
  double split_width = 0.25;      // (0, 4)
  double join_gap = 0.3;          // boxes one above the other (overlapping by half the narrower
                                  // width) with a vertical gap under this share of the taller
                                  // one's height merge (an object cut in two), 0..2
  void validate() const;          // throws roiflow::Error naming the bad value
};

// One frame's foreground: the mask of moving pixels at the model's resolution.
struct Foreground {
  long long observed = 0;  // frames the model had seen, this one included
  int scale = 1;           // full-resolution pixels per mask pixel
  cv::Size frame_size;     // full resolution
  cv::Mat mask;            // CV_8U, 255 = moving (shadows are background)
  cv::Mat integral;        // CV_32S integral of mask / 255
  // CV_32S integral of the pixels (model resolution) whose gray level changed by more than
  // MotionDetectorParams::change_level since `change_frames` frames back (since the first frame
  // while fewer were seen); empty in the first frame.
  // The model's foreground also holds ghosts: background that an object uncovered after
  // standing in it (or since the first frame); a ghost does not change.
  cv::Mat changed;
  // Scene start with the frames' flow: per pixel (model resolution, CV_32FC2) its motion since
  // the previous frame less the frame's median motion, in full-resolution pixels (NaN where the
  // window is too weakly textured to tell, MotionDetectorParams::start_texture); else empty.
  cv::Mat motion;
  long long absorbed = 0;  // pixels (model resolution) held as absorbed ghosts in this frame

  // Share of moving pixels inside `box` (full-resolution pixels, clipped to the frame); 0 for
  // an empty or outside box.
  double moving_share(const cv::Rect2f& box) const;
  // Share of changed pixels inside `box`; 1 while `changed` is empty (nothing to tell).
  double changed_share(const cv::Rect2f& box) const;
  bool empty() const { return mask.empty(); }
};

class MotionDetector {
 public:
  explicit MotionDetector(const MotionDetectorParams& params = {});
  const MotionDetectorParams& params() const { return params_; }
  // The background refresh: updates the model with `image` (8-bit BGR or gray, one size for a
  // run, in order) and returns its foreground. Throws roiflow::Error on a size change.
  // `back` (given when wants_flow() said so, else ignored): dense LK from this frame back to the
  // previous one over the whole frame, flow (CV_32FC2: per pixel of `image` its displacement to
  // the previous frame) and confidence (CV_32F, the window's smallest structure eigenvalue).
  // `executor` (may be null): runs the background model's bands of rows at once (banded_mog2.hpp);
  // the first frame fixes their count from its concurrency. The result does not depend on it.
  Foreground observe(const cv::Mat& image, const flow::FlowResult* back = nullptr,
                     const Executor* executor = nullptr);
  // Whether the next observe() is in the scene start and uses the flow back to the previous
  // frame (from the second frame to the `start_frames`-th one after it, when `start_motion` > 0).
  bool wants_flow() const;

 private:
  MotionDetectorParams params_;
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// Whether frame `index` (0-based, in the order observed) is in the scene start and takes the
// flow back to the previous frame: MotionDetector::wants_flow() for a pipeline that computes that
// flow ahead of the background refresh.
bool wants_flow(const MotionDetectorParams& params, long long index);

// The smallest object's box area in full-resolution pixels for a model working `scale` times
// smaller than the frame: min_area, or min_model_area model pixels where that is less.
double smallest_object(const MotionDetectorParams& params, int scale);

// The moving objects of one foreground (score = area in full-resolution pixels), biggest first;
// empty during the warm-up. Thread-safe (reads only `fg`).
std::vector<Detection> detect_objects(const Foreground& fg, const MotionDetectorParams& params);

// Merges boxes whose intersection covers at least `overlap` of the smaller box, or that stand one
// above the other with a gap under `join_gap` of the taller height, into their union, until no
// such pair is left.
std::vector<cv::Rect2f> merge_nested(std::vector<cv::Rect2f> boxes, double overlap,
                                     double join_gap = 0);

}  // namespace roiflow::tracking
