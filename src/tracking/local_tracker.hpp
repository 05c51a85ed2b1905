// LocalTracker: the paper's local treatment. One object followed from frame to frame by dense LK
// on a local region around its predicted position, at the pyramid level of the object's scale,
// checked forward-backward, corrected against the target's appearance, and declared lost (with
// a reason) when the measurement cannot be right; docs/LOCAL_TRACKER.md has the details.
//
//   using namespace roiflow;
//   tracking::LocalTracker local;                              // paper defaults: ROI 50, LK 10/3/3
//   local.start({frame_t, nullptr}, {70, 51, 107, 87});     // appearance captured from frame t
//   const tracking::LocalResult r = local.track({frame_t1, nullptr});  // frame t -> frame t+1
//   if (r.lost) local.restart({frame_t1, nullptr}, r.box);  // where the global treatment found it
//   std::cout << r.box << " moved " << r.velocity << " px\n";
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"

namespace roiflow::tracking {

struct LocalTrackerParams {
  int roi = 50;  // least side of the local region in pixels (the paper's 50x50), 8..4096
  flow::LkParams lk = flow::LkParams::paper();
  bool whole_frame = false;       // LK over the whole frame (the paper's global-mode baseline)
  int lk_context = 4;             // pixels of LK context around the region at each level
                                  // (flow::FlowOptions::context): the region already holds the
                                  // object with a margin, and the exact context (-1) would cost
                                  // several times the region itself; -1..1000
  int max_points = 512;           // object pixels sampled (a regular grid over the box), 16..1e6
  double lk_patches = 2;          // LK runs on the finest pyramid level where the object's
                                  // shorter side still spans this many LK patches (its flow
                                  // upsampled to full resolution), so that a large object
                                  // costs what a small one does; 0 = always full resolution,
                                  // 0..100 (whole_frame mode always runs at full resolution)
  int fb_levels = 1;              // pyramid levels of the backward LK (at most lk.levels), 1..6: it
                                  // starts from the reverse of the measured motion, so only the
                                  // residual is left to find and coarse levels would cost more
                                  // (their margins) than they help
  double fb_threshold = 1.0;      // forward-backward error in pixels above which a pixel is an
                                  // outlier, > 0
  double min_inliers = 0.25;      // lost below this share of the object's pixels passing the
                                  // forward-backward check, [0, 1)
  double min_texture = 1e-5;      // lost when the median smallest eigenvalue of the object's LK
                                  // structure tensors (intensities in [0, 1]) is below this, >= 0
  double min_appearance = 0.3;    // lost when the best NCC against the template is below this,
                                  // [-1, 1)
  double trust_appearance = 0.5;  // the appearance corrects the box only from this NCC on,
                                  // [min_appearance, 1]
  double appearance_weight = 0.5;  // how far the box moves to the appearance match, [0, 1]
  double search = 0.15;            // appearance search radius, as a share of the box's shorter
                                   // side (at least 3 pixels of the match level), (0, 2]
  double scale_step = 0.0125;      // relative step between the matched scales, (0, 0.5): finer
                                   // steps over a wider range than the paper's 3 scales 3 % apart
                                   // size small targets better (docs/BENCHMARK.md)
  int scale_steps = 5;             // scales matched on each side of the measured one, 0..10
  int match_side = 20;             // the shorter side the template is matched at (the finest
                                   // pyramid level where the object is at least this size), 8..256
  int template_interval = 10;      // frames between refreshes of the recent appearance (taken
                                   // only from confidently tracked frames), >= 1
  double velocity_gain = 0.5;      // share of the prediction error that corrects the velocity,
                                   // [0, 1]
  // Self-awareness and non-rigid targets (docs/TRACKING.md, "Knowing when it is lost").
  bool segment = true;                // the target's motion from the pixels that move unlike the
                                      // background (measured on a ring around the box)
  double foreground_tolerance = 1.0;  // pixels of the LK level by which a pixel's flow must differ
                                      // from the background's to move with the target, > 0
  double max_fb_error = 4;       // the flow fails when the median forward-backward error of the
                                 // object's pixels exceeds this many pixels of the LK level, > 0
  double max_frame_share = 0.9;  // lost when a side of the box exceeds this share of the
                                 // frame's, (0, 1]
  double moving_speed = 1.5;     // the target "was moving" when its recent speed relative to the
                                 // background is above this (pixels per frame), > 0
  double stop_share = 0.25;      // ... and it is taken to have latched onto the background when
                                 // its speed relative to it drops below this share of that
                                 // recent speed at once, with no pixel moving unlike it, [0, 1)
  double confident_appearance = 0.6;  // the appearance memory is refreshed only from frames whose
                                      // NCC reaches this, [trust_appearance, 1]
  int memory = 4;            // earlier looks kept besides the first (long-term memory), 0..16
  int memory_interval = 25;  // confident frames between two looks kept, >= 1
  double coast_decay = 0.9;  // velocity kept per frame while lost (coasting), [0, 1]
  bool follow_lost = true;   // while lost, the box follows the flow where its checks pass (the
                             // target seen from a side no look shows, most often) instead of
                             // coasting; still reported lost until a look confirms it
  double lost_prior = 0;     // while lost, a match at the search's edge ranks this much NCC below
                             // an equal one at the prediction (tracking::MatchPrior), [0, 1]; off:
                             // 0.05 and 0.1 moved the dev set's sequences both ways
                             // (docs/BENCHMARK.md)
  double max_reach = 8;      // while lost, the appearance search around the coasting box widens
                             // from 2 to this many times `search`, 2..100
  int scale_check_interval = 10;    // every this many held frames the first look is matched at
                                    // 17 sizes 5 % apart (0.68-1.48 of the box), each searched over
                                    // the whole window: a size 10 % or more from the box's that
                                    // beats the box's own by scale_check_margin, on two frames in a
                                    // row, takes the box half-way to it (the flow's scale measures
                                    // the box's content, background included, and the step's own
                                    // search sees only +-6 %); 0 = off, 0..1000
  double scale_check_margin = 0.1;  // NCC by which that size must beat the box's, (0, 1]
  void validate() const;            // throws roiflow::Error naming the bad value
};

// One frame for the local treatment.
struct LocalFrame {
  cv::Mat gray;  // 8-bit single channel
  // Optional: the whole frame's pyramid, built from `gray` with lk.levels and lk.sigma (a
  // pipeline builds it in parallel for the whole-frame mode); may be null.
  std::shared_ptr<const flow::Pyramid> pyramid;
};

// Why a frame's result is lost (Found when it is not).
enum class LostReason {
  Found,
  FewInliers,  // too few pixels pass the forward-backward check
  LowTexture,  // nothing in the box for LK to hold on to
  Appearance,  // the box matches none of the target's looks (first, recent, remembered)
  LeftRegion,  // the measured centre left the local region
  FbError,     // the median forward-backward error is high
  ScaleJump,   // the box grows or shrinks faster between two frames than any object does
  TooLarge,    // the box is (nearly) as large as the frame
  Background,  // the box moves with the background right after the target moved unlike it
  Searching,   // lost before, and not yet found again by appearance
  Collapsed,   // tracking::Tracker: the box's part inside the frame is under min_side on a side
  Still        // tracking::Tracker: no moving pixels in the box for still_frames frames
};
const char* to_string(LostReason reason);

struct LocalResult {
  cv::Rect2f box;        // the measured box in frame t; the prediction when lost
  cv::Point2f velocity;  // pixels per frame, after correction
  bool lost = false;
  LostReason reason = LostReason::Found;
  cv::Rect region;         // where forward LK ran (frame t-1 pixels)
  cv::Mat region_flow;     // CV_32FC2 forward flow over `region`, owned by the result
  double inliers = 0;      // share of the object's pixels that passed the forward-backward check
  double texture = 0;      // median smallest eigenvalue over the object's pixels
  double appearance = -1;  // best NCC against the template, -1 when it was not measured
  double scale = 1;        // size change this frame (1 = none)
  int level = 0;           // the pyramid level LK ran on (see lk_patches)
  double fb_error = 0;     // median forward-backward error of the object's pixels (level-0 px)
  bool background_known = false;  // the ring around the box gave the background's motion
  cv::Point2f background;         // its motion (median flow of the ring), pixels per frame
  double foreground = 0;          // share of the inliers that move unlike the background
  bool by_look_alone = false;     // held, but the flow failed: the look alone placed the box
                                  // (its NCC is `appearance`)
};

class LocalTracker {
 public:
  // `executor` splits LK into row stripes (nullptr = serial); it must outlive the tracker.
  // Throws roiflow::Error on bad params.
  explicit LocalTracker(const LocalTrackerParams& params = {}, const Executor* executor = nullptr);
  ~LocalTracker();
  LocalTracker(LocalTracker&&) noexcept;
  LocalTracker& operator=(LocalTracker&&) noexcept;

  const LocalTrackerParams& params() const;

  // Starts on `frame` at `box`: captures the target's appearance there and sets the velocity to
  // zero. Throws roiflow::Error when the frame is not 8-bit gray, when the box is not finite,
  // has a side below 2 pixels or leaves fewer than 2x2 pixels inside the frame, or when a
  // given pyramid is not the frame's.
  void start(const LocalFrame& frame, const cv::Rect2f& box);
  // Places the object again (after a re-detection) keeping the appearance captured by start().
  void restart(const LocalFrame& frame, const cv::Rect2f& box);
  // ... with a known velocity (pixels per frame): the next track() predicts the box there.
  void restart(const LocalFrame& frame, const cv::Rect2f& box, cv::Point2f velocity);
  bool started() const;
  // Best NCC of the target's looks (first, recent, remembered) around `box` in `frame`, at a few
  // scales: how well a re-detection there matches; -1 when nothing could be matched. Does not
  // change the state.
  double verify(const LocalFrame& frame, const cv::Rect2f& box);
  // Whether the last track() left the target lost (the box coasts until it is found again).
  bool lost() const;

  // Follows the object from the previous frame to `frame` (same size as the previous one,
  // else roiflow::Error). Throws roiflow::Error when not started.
  LocalResult track(const LocalFrame& frame);

  cv::Rect2f box() const;        // the current box (measured or coasted)
  cv::Point2f velocity() const;  // pixels per frame
  cv::Rect2f predicted() const;  // where the constant-velocity prediction puts the next box

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace roiflow::tracking
