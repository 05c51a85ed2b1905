// MultiTracker: every moving object of a fixed camera, each followed by LK in its own region.
//
//   #include <iostream>
//   using namespace roiflow;
//   tracking::MultiTracker tracker;                          // fixed camera, nothing known
//   long long index = 0;
//   for (const cv::Mat& gray : {frame_t, frame_t1}) {     // the frames of a fixed camera
//     tracking::MotFrame out = tracker.process(index++, gray, bgr);  // gray and colour picture
//     for (const tracking::MotObject& o : out.objects)
//       if (!o.lost) std::cout << o.id << " " << o.box << "\n";
//   }
//
// The per-frame work is four steps, each a plain function, so that a pipeline (pipeline::run_mot)
// makes each a node and the state that links frames travels on its edges:
//  - plan_tiles(state at t) -> the LK tiles for frame t+1: one per object region (the object's
//    box at t plus a margin), regions taller than `tile_rows` split into row tiles.
//  - measure_tile(tile, pyramids of t and t+1, foreground of t) -> the tile's object pixels that
//    pass the forward-backward check and their motion; pixels inside another object's
//    overlapping box are not the object's own (in a crossing they move with the one in front)
//    and are left out. Thread-safe; one task per tile.
//  - MotionDetector::observe and detect_objects (tracking/motion_detector.hpp): the background
//    refresh and the global treatment (moving objects of the frame); after the scene start,
//    split_candidates and split_by_flow (tracking/motion_split.hpp) cut a detection much larger
//    than the one object it holds by its pixels' dense flow.
//  - decide(state at t, the frame's tile motions, foreground, detections) -> state at t+1: per
//    object a constant-velocity Kalman filter on its box (centre, size and their velocities; the
//    paper's Fig. 3 correction), predicted, then corrected by the detection the optimal
//    assignment (core/assignment.hpp) gives it (cost 1 - IoU with where LK or the prediction puts
//    it), or, where background-subtraction blobs merge (one blob over several objects) or no
//    detection is left, by its LK motion as long as its box holds moving pixels. Moving pixels
//    are the model's foreground where the frame also changed (Foreground::changed): a ghost (the
//    background uncovered where an object stood when the model learnt it) measures nothing and
//    starts nothing. Births: detections
//    no object explains, confirmed after `min_hits` consecutive frames, found on global frames
//    (every `global_interval` frames and whenever an object is lost). Deaths: lost for
//    `max_lost` frames, no moving pixels for `still_frames` frames, less than `min_visible` of
//    the box inside the frame, or a side under `min_side` pixels, or young and its own pixels
//    standing still for `parked_frames` (a ghost); an object that duplicates an
//    older one (IoU > 0.7, or 80% of its box inside an older one twice its size: a fragment)
//    for 3 frames ends too.
// A box that does not move with moving pixels, collapses or leaves the view is never reported
// found: it is lost (coasting, `lost`) until it ends.
#pragma once

#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "tracking/motion_detector.hpp"

namespace roiflow::tracking {

// A known target (--init, --init-file): its id (> 0) and box in the first frame.
struct KnownTarget {
  long long id = 0;
  cv::Rect2f box;
};

// Reads known targets, one `id,x,y,w,h` line each (ids >= 1, distinct; sides > 0; blank lines
// and lines starting with '#' skipped). Throws roiflow::Error as `path:line: what was wrong`.
std::vector<KnownTarget> read_known_targets(const std::string& path);
std::vector<KnownTarget> parse_known_targets(std::string_view text, const std::string& name);

struct MultiTrackerParams {
  MotionDetectorParams detector;
  flow::LkParams lk = flow::LkParams::paper();
  int lk_context = 4;           // LK context around a tile at each level (FlowOptions::context)
  int margin = 8;               // pixels around an object's box in its region, 0..1000
  int tile_rows = 64;           // regions taller than this split into row tiles, 8..4096
  int max_points = 256;         // object pixels sampled per object (a grid), 16..1e6
  double fb_threshold = 1.0;    // forward-backward error (pixels) above which a pixel is an
                                // outlier, > 0
  double min_inliers = 0.25;    // LK measures an object when this share of its sampled pixels
                                // passes the check, [0, 1)
  double lk_gate = 1.5;         // LK's motion counts only within this many pixels of the
  double lk_gate_share = 0.05;  // predicted one, or this share of the object's height, > 0
  double merge_area = 1.1;      // a detection over half of two objects' boxes and this many times
                                // larger than each is a merge of them (LK follows them), > 0
  double merge_own = 0.7;       // but not when one of them overlaps it this much (IoU): that one
                                // takes it, (0, 1]
  double lk_size_decay = 0.9;   // per frame an object follows LK alone, its size's speed is
                                // multiplied by this, [0, 1]
  double split_grow = 1.25;     // after the scene start, a detection over half of one object's
                                // predicted box (and of no other) and this many times its area
                                // is split by its pixels' motion (tracking/motion_split.hpp);
                                // 0 = never, else >= 1
  double split_keep = 0.7;      // the split keeps one motion's box alone (the rest of the
                                // detection standing still is cut) when it covers under this
                                // share of the detection, (0, 1]
  double min_moving = 0.08;     // share of moving pixels a box needs to count as moving, [0, 1)
  double min_changed = 0.02;    // and share of changed pixels (Foreground::changed: a ghost of
                                // the background model has none), [0, 1); a detection with
                                // fewer measures no object and starts none
  double gate_iou = 0.1;        // a detection farther from an object (IoU) is not its, [0, 1)
  int min_hits = 3;             // consecutive detections that confirm a birth, >= 1
  int max_lost = 12;            // frames an object coasts without a measurement before it ends
  int still_frames = 15;        // frames without moving pixels before an object ends
  int parked_frames = 3;        // a young object (age under `parked_age` frames) whose own pixels
  int parked_age = 10;          // stand still (LK motion under `parked_motion` pixels a frame)
  double parked_motion = 0.25;  // for this many frames in a row ends: a birth on a ghost (the
                                // uncovered background behind an object grows as the object
                                // leaves: its box moves, its pixels do not), >= 1, >= 0, >= 0
  double min_visible = 0.5;     // least share of the box inside the frame, (0, 1]
  int min_side = 8;             // an object whose box is narrower ends, >= 1
  int global_interval = 1;      // frames between global treatments (births), >= 1
  double size_noise = 0.1;      // a detection's width and height error, share of the height, > 0
  bool births = true;           // false: only the known targets are followed
  std::vector<KnownTarget> known;  // followed from the first frame
  void validate() const;           // throws roiflow::Error naming the bad value
};

// One object's Kalman filter: state (cx, cy, w, h, vx, vy, vw, vh), covariance row-major.
struct BoxFilter {
  std::array<double, 8> x{};
  std::array<double, 64> p{};

  static BoxFilter start(const cv::Rect2f& box, cv::Point2f velocity = {});
  void predict();
  // A detection: centre and size (size error `size_noise` of the height).
  void correct_box(const cv::Rect2f& box, double size_noise = 0.05);
  void correct_centre(cv::Point2f centre, double h);  // LK: the centre only
  cv::Rect2f box() const;
  cv::Point2f velocity() const;
};

struct Track {
  long long id = 0;  // 0 while tentative (not yet confirmed)
  BoxFilter filter;
  cv::Rect2f box;  // the corrected box in the frame decided last
  int hits = 0;    // consecutive frames with a detection, while tentative
  int lost = 0;    // consecutive frames without a measurement
  int still = 0;   // consecutive frames without moving pixels in the box
  int duplicate = 0;
  int parked = 0;      // consecutive frames its own pixels stood still (LK)
  bool known = false;  // a known target (no birth, no end for standing still)
  long long age = 0;
};

// What links frame t to frame t+1: the decisions at t.
struct TrackSet {
  long long frame = -1;  // index of the frame decided last (-1: none yet)
  cv::Size size;
  std::vector<Track> tracks;
  long long next_id = 1;
  long long born = 0, ended = 0, global_activations = 0;
};

// One LK task: part of an object's region in frame t, followed to frame t+1.
struct ObjectTile {
  std::size_t track = 0;         // index in TrackSet::tracks
  cv::Rect2f box;                // the object's box in frame t
  cv::Rect rows;                 // the part of its region this tile covers (frame t pixels)
  cv::Point2f velocity;          // predicted motion, the LK seed
  int step = 1;                  // grid step of the sampled object pixels
  bool foreground_only = false;  // sample only moving pixels of frame t
  // Other objects' boxes in frame t that overlap this one: their pixels are not sampled (where
  // two objects cross, the shared pixels follow whichever is in front).
  std::vector<cv::Rect2f> exclude;
};

struct TileMotion {
  std::size_t track = 0;
  std::vector<cv::Point2f> moves;  // motion of the sampled pixels that passed the check
  int sampled = 0;
  cv::Rect region;  // where forward LK ran
};

struct MotObject {
  long long id = 0;
  cv::Rect2f box;
  cv::Point2f velocity;
  bool lost = false;  // not measured this frame (box = prediction)
  cv::Rect region;    // where LK ran for this frame (may be empty)
};

// One decided frame, as the sinks see it.
struct MotFrame {
  long long index = 0;
  std::vector<MotObject> objects;                         // confirmed objects, lost ones flagged
  bool global = false;                                    // births were searched on this frame
  long long born = 0, ended = 0, global_activations = 0;  // running totals
  double ms = 0;                                          // tracker time of this frame
};

// The state before the first frame: the known targets, confirmed.
TrackSet initial_tracks(const MultiTrackerParams& params);
std::vector<ObjectTile> plan_tiles(const TrackSet& state, const Foreground& fg,
                                   const MultiTrackerParams& params);
// `lk` is the caller's workspace (one per thread); its params must be params.lk.
TileMotion measure_tile(const ObjectTile& tile, const flow::Pyramid& pyr_t,
                        const flow::Pyramid& pyr_t1, const Foreground& fg_t, flow::DenseLK& lk,
                        const MultiTrackerParams& params);
// Decides frame `index`; `motions` may come in any order. `frame` flags the global frame.
TrackSet decide(const TrackSet& state, long long index, cv::Size size,
                const std::vector<TileMotion>& motions, const Foreground& fg,
                const std::vector<Detection>& detections, const MultiTrackerParams& params,
                bool* global_frame = nullptr);
// The sinks' view of a decided state.
MotFrame report_frame(const TrackSet& state, const std::vector<TileMotion>& motions,
                      bool global_frame);

// The four steps in order, serially, for one frame at a time.
class MultiTracker {
 public:
  explicit MultiTracker(const MultiTrackerParams& params = {});
  ~MultiTracker();
  MultiTracker(MultiTracker&&) noexcept;
  MultiTracker& operator=(MultiTracker&&) noexcept;
  const MultiTrackerParams& params() const;
  // `gray`: 8-bit gray; `image`: the picture the background model learns (BGR or gray).
  MotFrame process(long long index, const cv::Mat& gray, const cv::Mat& image);
  const TrackSet& state() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace roiflow::tracking
