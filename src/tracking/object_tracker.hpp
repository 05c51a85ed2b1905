// ObjectTracker: the per-frame tracker interface of the drop-in stages (GStreamer element,
// Python module): frames in, the objects of each frame out, each with a stable id.
//
//   using namespace roiflow;
//   tracking::ObjectTrackerParams params;            // paper defaults (TrackerParams)
//   params.init = {{70, 51, 107, 87}, {300, 40, 30, 60}};   // empty: detect one moving object
//   params.max_lost = 25;                          // drop an object lost 25 frames in a row
//   tracking::ObjectTracker tracker(params);
//   cv::Mat gray(240, 320, CV_8UC1, cv::Scalar(0));
//   for (const tracking::TrackedObject& o : tracker.update({0, {}, gray, nullptr, nullptr}))
//     (void)o.id;
//
// Each object is one tracking::Tracker (local treatment, global fallback). With `init` boxes,
// one tracker per box follows that box from the first frame, ids 1, 2, ... in the boxes' order.
// Without, one tracker finds the moving object itself (the global treatment) and gets id 1
// once found. An object lost for more than `max_lost` frames in a row is dropped (0 = never):
// a dropped `init` object is gone for good, a detected one is replaced by a fresh detector whose
// object gets the next id. update() returns the objects known on that frame, lost ones
// included (their box is the prediction), in id order. primary() is the TrackerOutput of the
// first slot on the last frame, the record `roiflow track` logs for the same input and params.
// Several objects from one detector (multi-object tracking) fit the same interface.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/executor.hpp"
#include "tracking/tracker.hpp"

namespace roiflow::tracking {

struct TrackedObject {
  int id = 0;                                         // 1, 2, ... stable while the object lives
  cv::Rect2f box;                                     // top-left corner and size, pixels
  cv::Point2f velocity;                               // pixels per frame
  TrackRecord::Mode mode = TrackRecord::Mode::Local;  // the treatment that produced the box
  bool lost = false;                                  // not found on this frame (box = prediction)
  int lost_frames = 0;                                // frames lost in a row, this one included
};

struct ObjectTrackerParams {
  TrackerParams tracker;         // every object's; its `init` is ignored (see `init`)
  std::vector<cv::Rect2f> init;  // boxes in the first frame; empty = detect one object
  int max_lost = 0;              // frames lost in a row before an object is dropped; 0 = never
  void validate() const;         // throws roiflow::Error naming the bad value
};

class ObjectTracker {
 public:
  // `executor` as for Tracker (nullptr = serial); it must outlive the tracker. Throws
  // roiflow::Error on bad params.
  explicit ObjectTracker(const ObjectTrackerParams& params, const Executor* executor = nullptr);
  ~ObjectTracker();
  ObjectTracker(ObjectTracker&&) noexcept;
  ObjectTracker& operator=(ObjectTracker&&) noexcept;

  // Frames in order, one size for the run (Tracker::process's contract and errors).
  std::vector<TrackedObject> update(const TrackerInput& frame);
  // The first slot's output on the last frame (the object with id 1 while it lives).
  const TrackerOutput& primary() const;
  // Pyramid needs of the trackers (a pipeline may skip whole-frame pyramids when false).
  bool wants_pyramid() const;
  int pyramid_levels() const;
  double pyramid_sigma() const;
  long long frames() const;  // frames given to update()
  void finish_background_work();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace roiflow::tracking
