// BoxTracker: one interface over the single-object trackers a benchmark compares — roiflow's
// Tracker (the same code path as `roiflow track --init`) and OpenCV's CSRT, KCF, MOSSE and
// MedianFlow (opencv_contrib's tracking module) — so that each runs on the same frames and
// reports, per frame, a box and whether it considers the target lost.
//
//   using namespace roiflow;
//   video::VideoSource source("data/tracking/Car4");
//   std::unique_ptr<tracking::BoxTracker> t = tracking::make_box_tracker("csrt");
//   std::optional<video::Frame> f = source.next();
//   tracking::BoxUpdate u = t->start(*f, tracking::bgr_picture(*f), cv::Rect2f(70, 51, 107, 87));
//   while ((f = source.next())) u = t->next(*f, tracking::bgr_picture(*f));
//
// start() gives the first frame and the target's box there and answers that box (OTB's
// protocol: a tracker's first box is its initialisation). next() gives each later frame in order.
// Every tracker gets the frame as decoded (`frame`, roiflow reads its gray plane and asks for
// colour when it needs it) and the same picture as 8-bit BGR (`bgr`, made by the caller outside
// any timing: OpenCV's trackers want three channels, gray videos included).
//  - roiflow: tracking::Tracker with `init` set to the box, no executor (all its work on the
//  calling
//    thread); whole-frame pyramids are built when it asks for them (Tracker::wants_pyramid), as
//    the pipeline does. lost = TrackerOutput::lost.
//  - OpenCV: cv::TrackerCSRT and cv::TrackerKCF (integer boxes: the box is rounded),
//    cv::legacy::TrackerMOSSE and cv::legacy::TrackerMedianFlow, default parameters. lost =
//    update() returned false; the box then stays the last one reported (OpenCV leaves it
//    unchanged). An OpenCV exception inside init() or update() counts as lost, not as an error
//    of the run: from a failed init() on, every frame is lost at the initial box.
// Callers should run OpenCV single-threaded (cv::setNumThreads(1)) when they time the calls
// with a thread's CPU clock, so that all work happens on the calling thread.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "tracking/tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::tracking {

struct BoxUpdate {
  cv::Rect2f box;
  bool lost = false;
};

class BoxTracker {
 public:
  virtual ~BoxTracker() = default;
  virtual BoxUpdate start(const video::Frame& frame, const cv::Mat& bgr, const cv::Rect2f& box) = 0;
  virtual BoxUpdate next(const video::Frame& frame, const cv::Mat& bgr) = 0;
};

// "roiflow", "csrt", "kcf", "mosse", "medianflow", in this order.
const std::vector<std::string>& box_tracker_names();

// `roiflow` configures roiflow's tracker (its `init` is set by start()). Throws roiflow::Error
// for a name not in box_tracker_names(), listing them.
std::unique_ptr<BoxTracker> make_box_tracker(std::string_view name,
                                             const TrackerParams& roiflow = {});

// "" for a name in box_tracker_names(), else "unknown tracker 'NAME' (known: roiflow,csrt,...)".
std::string box_tracker_check(std::string_view name);

// The frame's picture as 8-bit BGR (a gray picture converted), a new Mat or the frame's own.
cv::Mat bgr_picture(const video::Frame& frame);

}  // namespace roiflow::tracking
