// Tracker: the paper's system for one object. The local treatment (LocalTracker) follows the
// target while it is found; the global treatment (GlobalDetector) finds a moving object when
// none is known or the target is lost; global mode (the paper's baseline) runs LK over the
// whole frame every frame. docs/LOCAL_TRACKER.md describes a frame's steps.
//
//   using namespace roiflow;
//   tracking::TrackerParams params;                    // paper defaults: ROI 50, LK 10x10/3/3
//   params.init = cv::Rect2f(70, 51, 107, 87);       // OTB protocol; leave empty to detect
//   tracking::Tracker tracker(params);
//   video::VideoSource source("car.mp4");
//   while (std::optional<video::Frame> f = source.next()) {
//     tracking::TrackerInput in{f->index, f->image, f->gray, nullptr, f->deferred_image};
//     if (tracker.wants_pyramid()) {                 // optional: a pyramid built outside
//       in.pyramid = std::make_shared<flow::Pyramid>(
//           flow::build_pyramid(f->gray, tracker.pyramid_levels(), tracker.pyramid_sigma()));
//     }
//     const tracking::TrackerOutput out = tracker.process(in);
//     if (out.has_target) std::cout << eval::track_csv_row(out.record());
//   }
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string_view>

#include "core/executor.hpp"
#include "eval/track_log.hpp"
#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "tracking/global_detector.hpp"
#include "tracking/local_tracker.hpp"
#include "video/deferred_image.hpp"

namespace roiflow::tracking {

// The record the track log holds (eval/track_log.hpp); TrackerOutput::record() fills it.
using eval::TrackRecord;

enum class TrackMode { Local, Global };

struct TrackerParams {
  TrackMode mode = TrackMode::Local;
  int roi = 50;  // side of the local region in pixels (the paper's 50x50), 8..4096; the region
                 // grows beyond it to hold a larger object and its motion
  flow::LkParams lk = flow::LkParams::paper();
  std::optional<cv::Rect2f> init;  // the target's box in the first frame (OTB protocol)
  // The rest of the local treatment (forward-backward check, appearance correction, thresholds
  // of the decision); its roi, lk and whole_frame are taken from roi, lk and mode above.
  LocalTrackerParams local;
  // Background flow (median over the local region outside the object, pixels per frame) above
  // which the camera is taken to move: the background model then sees everything move, so a lost
  // target is searched by appearance, as when it came from `init`. > 0.
  double camera_motion = 1.0;
  // Without `init`, the background model that finds the object again is refreshed every
  // `observe_interval` frames while the local treatment holds the target (every frame while the
  // global treatment searches, and on the frame the target is lost). It only has to stay
  // current enough for a later re-detection; refreshing it every frame would cost several times
  // the local treatment itself (MOG2 on a 320x240 copy: ~2 ms, plus the frame's colour
  // conversion). It runs beside the frames, but on two cores it takes the time of decoding or
  // tracking all the same: every 32nd frame it cost a fifth of tracking's frames/s at 640x480
  // (pipeline_bench TrackVsDecode: 2.3-2.6k frames/s, 2.9-3.0k at 64; the demo's AUC
  // unchanged, global activations vtest 11 -> 8, bgslibrary 8 -> 9). 1..1000.
  int observe_interval = 64;
  // When the local treatment loses a held target, it tries once more from the frame before,
  // predicting the target where the whole picture's shift (tracking::camera_shift) and the target's
  // motion relative to the background take it: a camera that jumps moves the target further
  // than its velocity predicts.
  bool camera_retry = true;
  // While the target is held, each refresh learns as much as observe_interval x held_learning
  // frames of video: the model forgets more slowly than while searching (1 / held_learning times
  // its history), so that a slow target it sees in every refresh is not learnt into the
  // background. (0, 1].
  double held_learning = 0.25;
  // A re-detection of a lost target is accepted when one of the target's looks matches it with
  // at least this NCC (LocalTracker::verify), [-1, 1].
  double verify = 0.65;
  // ... and far from where it was last held (beyond 1.5 box sides, growing by reach_growth
  // sides a frame lost) only from this NCC on, [verify, 1].
  double verify_far = 0.9;
  // How fast "near" grows while the target stays lost: box sides per frame, [0, 10].
  double reach_growth = 0.05;
  // While the target stays lost, the whole-frame search runs every this many frames, 1..1000.
  int redetect_interval = 1;
  // ... and its colours (hue and saturation) must match one of the target's colour looks
  // (GlobalDetector::colour_similarity: the first, and recent ones kept every colour_interval
  // frames while the target is held confidently) at least this much: gray NCC alone takes
  // another car or person of the same shape; [-1, 1] (-1 = no colour check).
  double colour_verify = 0.6;
  int colour_interval = 32;  // 1..1000
  // A re-detection short of verify_far is held provisionally and taken only once it has held on
  // confirm_frames consecutive lost frames: followed from frame to frame by its own look
  // (normalised cross-correlation within a box side), its NCC with the target's looks at least
  // confirm_verify and its colours matching (colour_verify), so that a lookalike the search
  // returns for one frame (another person during fast camera motion) does not capture the track.
  // Meanwhile the target is reported lost, its box at the provisional one. 1 = take it at once;
  // 1..100.
  int confirm_frames = 2;
  double confirm_verify = 0.5;  // [-1, 1]
  // A box the local treatment placed by its look alone (the flow failed: a camera jump, an
  // occlusion) with a look short of local.confident_appearance is not taken for the target: a
  // person or car next to it matches about as well. The target is reported lost, the box stays
  // where the look put it, and, as after any loss, a box the local treatment holds again is taken
  // for the target only once its colours match one of the target's colour looks (colour_verify),
  // as a re-detection's must. false: the local treatment's word is taken as it is.
  bool check_recovery = true;
  // A held box whose part inside the frame is narrower or lower than this is lost (a box that
  // collapsed, or hugs the border with the object outside the view), pixels, [0, 1000].
  double min_side = 8;
  // Without `init` (the target was found by its motion): a held box is lost once it has held no
  // moving pixels for this many frames in a row (0 = never). A pixel moves when it differs by
  // more than still_level grey levels from the same pixel 4 frames back; a box with at most
  // still_share of its pixels moving holds none. A camera that moves makes every box move: the
  // rule is a guard for fixed cameras. still_frames 0..100000, still_level [0, 255], still_share
  // [0, 1].
  int still_frames = 15;
  double still_level = 35;
  double still_share = 0.05;
  GlobalDetectorParams detector;
  void validate() const;  // throws roiflow::Error naming the bad value
};

// One frame as the pipeline hands it over. The pyramid, when given, is the whole frame's, built
// from `gray` with pyramid_levels() and pyramid_sigma(); it may be null: the tracker then
// builds what it needs itself. While the local treatment holds the target it needs none (it
// builds pyramids of its region only); wants_pyramid() tells a pipeline when to build them.
struct TrackerInput {
  long long index = 0;
  cv::Mat image;                                 // as decoded, 8-bit BGR or gray; may be empty
  cv::Mat gray;                                  // 8-bit gray
  std::shared_ptr<const flow::Pyramid> pyramid;  // optional
  // Optional: the picture when `image` is empty, made only if the tracker needs colour for this
  // frame (to learn the background or the target's appearance, or to search for it when lost).
  // Without either, the tracker works on gray.
  std::shared_ptr<const video::DeferredImage> deferred_image;

  cv::Mat picture() const { return video::picture_of(image, deferred_image, gray); }
};

struct TrackerOutput {
  long long index = 0;
  bool has_target = false;  // false until the target is known (given or detected)
  cv::Rect2f box;           // the target's box in this frame (valid when has_target)
  cv::Point2f velocity;     // pixels per frame, corrected estimate
  TrackRecord::Mode mode = TrackRecord::Mode::Global;  // the treatment that produced the box
  bool lost = false;  // the target was not found in this frame (box = prediction)
  LostReason reason = LostReason::Found;  // why the local treatment lost it (Found when it did not)
  cv::Rect region;                        // where LK ran for this frame (empty when it did not run)
  cv::Mat region_flow;  // CV_32FC2 flow over `region` (t-1 -> t), for annotation; may be empty
  double ms = 0;        // time process() took
  long long global_activations = 0;  // running count, this frame included

  TrackRecord record() const;  // 1-based frame = index + 1, as the track log wants
};

class Tracker {
 public:
  // `executor` splits LK over row tiles of the region and runs the background model's refresh
  // beside the frames while the target is held (nullptr = everything serial, at once); it must
  // outlive the tracker. The results never depend on it. Throws roiflow::Error on bad params.
  explicit Tracker(const TrackerParams& params, const Executor* executor = nullptr);
  ~Tracker();
  Tracker(Tracker&&) noexcept;
  Tracker& operator=(Tracker&&) noexcept;

  int pyramid_levels() const;
  double pyramid_sigma() const;

  // Frames must come in order, one size for the run. Throws roiflow::Error on a frame whose size
  // differs from the first one's or an `init` box outside the first frame.
  TrackerOutput process(const TrackerInput& frame);

  long long global_activations() const;

  // Whether whole-frame pyramids help the next frames: in global mode and until the target is
  // known. Without one the tracker builds what it needs, so this only saves a pipeline the
  // work (the result is the same either way). Thread-safe: a pipeline asks it while process()
  // runs on another thread.
  bool wants_pyramid() const;

  // Waits for the work the tracker started beside its frames through the executor (the
  // background refresh) and rethrows what it threw. A pipeline calls it before the threads that
  // run that work go away; the destructor waits too.
  void finish_background_work();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

const char* to_string(TrackMode mode);
TrackMode track_mode_from_string(std::string_view name);  // "local" | "global"

}  // namespace roiflow::tracking
