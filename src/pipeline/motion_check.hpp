// Motion check: does every object a track log reports as found move with moving pixels?
//
//   using namespace roiflow;
//   video::VideoSource video("vtest.avi");
//   const auto log = eval::read_track_csv("track.csv");
//   pipeline::MotionCheck c = pipeline::check_motion([&] { return video.next(); }, log);
//   if (!c.violations.empty()) std::cout << c.violations[0].id << "\n";
//
// The video is played through a background model of its own (tracking::MotionDetector, the
// tracker's defaults), independent of the tracker's. For each object, the check counts runs of
// consecutive frames where the log reports it found (local and not lost) while its box holds
// almost no moving pixels (share at most `still_share`) or its part inside the frame has a side
// under `min_side` pixels. A run longer than `max_run` frames is a violation: a box sitting on
// empty background, a collapsed box, or one hugging the border with the object outside the view.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/track_log.hpp"
#include "pipeline/frame_graph.hpp"
#include "tracking/motion_detector.hpp"

namespace roiflow::pipeline {

struct MotionCheckParams {
  // The check's own model of moving pixels: OpenCV's MOG2 background (ratio 0.9, which calls
  // fewer pixels moving than the tracker's, and no ghost absorption), so that the check does not
  // follow the tracker's tuning.
  tracking::MotionDetectorParams detector = [] {
    tracking::MotionDetectorParams p;
    p.background_ratio = 0.9;
    p.ghost_frames = 0;  // the model's own foreground: no ghost absorbed
    p.start_frames = 0;  // nor the background its first frames uncover
    return p;
  }();
  double still_share = 0.02;  // a box with at most this share of moving pixels has none
  double min_side = 8;        // pixels
  long long max_run = 30;     // frames
};

struct MotionViolation {
  long long id = 0;
  long long first = 0, last = 0;  // 1-based frames of the run
  std::string what;               // "no moving pixels" | "collapsed"
};

struct MotionCheck {
  long long frames = 0;   // frames of the video read
  long long records = 0;  // found records checked
  long long still = 0;    // of them, boxes without moving pixels
  long long small = 0;    // of them, boxes under min_side
  long long longest = 0;  // longest run of either, frames
  long long objects = 0;  // distinct ids
  std::vector<MotionViolation> violations;
};

MotionCheck check_motion(const FrameSource& video, const std::vector<eval::TrackRecord>& log,
                         const MotionCheckParams& params = {});
// {"frames", "objects", "records", "still", "small", "longest_run", "violations": [{"id",
// "first", "last", "what"}]}
nlohmann::ordered_json to_json(const MotionCheck& c);
// One line of counts, then one line per violation; each ends in '\n'.
std::string motion_check_text(const MotionCheck& c, long long max_run);

}  // namespace roiflow::pipeline
