// Multi-object tracking run: the MOT graph (run_mot) with its sinks — the track log with an id
// column, the MOTChallenge file, the annotated video and the summary.
//
//   using namespace roiflow;
//   video::VideoSource source("vtest.avi", {});
//   pipeline::MotRunOptions o;                       // fixed camera, every moving object
//   o.log = "track.csv";                             // frame,id,x,y,w,h,vx,vy,mode,lost,ms
//   o.mot = "mot.txt";                               // frame,id,x,y,w,h,conf,-1,-1,-1
//   pipeline::MotRun run = pipeline::track_objects([&] { return source.next(); },
//                                                  source.size(), source.fps(), o);
//   std::cout << run.summary.dump(2);                // objects_born, objects_ended, ...
//
// The track log gets one line per object and frame (lost objects too, flagged); the MOT file
// only the objects found in that frame, 1-based like MOTChallenge's ground truth (frame 1 is
// the first frame read, x and y are the box's top-left corner plus one). The MOT file and the
// summary are written atomically at the end; the log and the video are written as frames come.
#pragma once

#include <atomic>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "eval/mot.hpp"
#include "pipeline/frame_graph.hpp"
#include "pipeline/signals.hpp"
#include "tracking/multi_tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {

struct MotRunOptions {
  tracking::MultiTrackerParams params;
  std::string log;    // track log (.csv or .json); empty = none
  std::string mot;    // MOTChallenge file; empty = none
  std::string video;  // annotated video or PNG folder; empty = none
  int threads = 0;    // GraphOptions::threads
  int in_flight = 0;  // GraphOptions::max_in_flight
  bool progress = false;
  long long frame_hint = 0;  // frames expected (progress bar), 0 = unknown
  const std::atomic<bool>* cancel = nullptr;
  // Optional: sees every decided frame after the sinks above (tests, the demo).
  std::function<void(const MotTrackedFrame&)> on_frame;
};

struct MotRun {
  RunReport report;
  nlohmann::ordered_json summary;  // frames, fps, tracker_fps, objects_born, objects_ended, ...
  RunEnd end = RunEnd::Complete;   // set by track_objects_video
};

MotRun track_objects(const FrameSource& source, cv::Size size, double fps,
                     const MotRunOptions& options);

// The known targets of `roiflow track`: each "x,y,w,h" of `boxes` (ids 1, 2, ...) or the
// id,x,y,w,h lines of `file` (one of the two at most). Throws UsageError on bad text.
std::vector<tracking::KnownTarget> known_targets(const std::vector<std::string>& boxes,
                                                 const std::string& file);

// track_objects over a video: throws UsageError before the first frame when a known target has
// less than 2x2 pixels inside the frame; the summary gets "input" and "status" (the source's,
// or how the run ended), and `end` says how it ended.
MotRun track_objects_video(video::VideoSource& source, const MotRunOptions& options);

// The summary for people: frames, rates, global activations, lost records, threads, objects
// born and ended; lines ending in '\n'.
std::string objects_summary_text(const std::string& what, const nlohmann::ordered_json& summary);

// An object of frame `index` (0-based) as a MOTChallenge box: frame index + 1, the top-left
// corner plus one (MOTChallenge counts pixels from 1), confidence 1 (eval::write_mot writes it).
eval::MotBox mot_box(long long index, const tracking::MotObject& object);

}  // namespace roiflow::pipeline
