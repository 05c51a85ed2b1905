// The motion split after the scene start: a detection that the objects followed say is wrong —
// much larger than the one object it holds (a still tail of foreground joined to it, or another
// object beside it) — is cut by the motion of its
// pixels, from dense LK over just its box and a margin, back from its frame to the previous one.
// As in the scene start (start_motion_impl.hpp), a fixed camera's background does not move: its
// moving pixels (less the region's background motion) that gather around several distinct
// velocities are one object each; with one motion and a large part of its foreground standing
// still, the box shrinks to the moving pixels (a vehicle with the empty lane below it).
//
//   using namespace roiflow;
//   tracking::MultiTrackerParams params;
//   flow::DenseLK lk(params.lk);
//   flow::Pyramid pyr_t, pyr_t1;  // two frames of a fixed camera
//   flow::build_pyramid(frame_t, params.lk.levels, params.lk.sigma, pyr_t);
//   flow::build_pyramid(frame_t1, params.lk.levels, params.lk.sigma, pyr_t1);
//   tracking::MotionDetector detector(params.detector);
//   detector.observe(frame_t);
//   const tracking::Foreground fg_t1 = detector.observe(frame_t1);
//   auto detections = tracking::detect_objects(fg_t1, params.detector);
//   const tracking::TrackSet state = tracking::initial_tracks(params);  // decisions at t
//   const auto which = tracking::split_candidates(state, detections, fg_t1, params);
//   std::vector<std::vector<cv::Rect2f>> parts;
//   for (std::size_t j : which)
//     parts.push_back(tracking::split_by_flow(detections[j].box, pyr_t, pyr_t1, fg_t1, lk,
//     params));
//   detections = tracking::apply_splits(detections, which, parts);
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "tracking/motion_detector.hpp"
#include "tracking/multi_tracker.hpp"

namespace roiflow::tracking {

// Indices of the detections (frame t+1) that need the motion split, given the decisions at t:
// those that hold over half of the predicted box of exactly one confirmed object and are at
// least MultiTrackerParams::split_grow times its area (one over two objects is a merge, which
// the objects' LK follows: decide). None when split_grow is 0 or while the foreground carries
// the scene start's motion (the detector split those already).
std::vector<std::size_t> split_candidates(const TrackSet& state,
                                          const std::vector<Detection>& detections,
                                          const Foreground& fg_t1,
                                          const MultiTrackerParams& params);

// The motion split of one detection `box` of frame t+1: dense LK (params.lk, context
// params.lk_context) over the box plus params.margin, from t+1 back to t. Its foreground pixels
// (fg_t1) moving unlike the region's background (the median motion of its pixels outside the
// foreground) by detector.start_motion, in windows as textured as the background's median one
// (detector.start_texture), less detector.start_reach, gather in motions
// (detail::motion_modes). Returns the boxes that replace the detection: one per motion when
// there are two or more, or the one motion's box when it covers under `split_keep` of the box
// and a quarter of the foreground outside it does not move (under start_motion);
// empty: keep the detection as it is.
std::vector<cv::Rect2f> split_by_flow(const cv::Rect2f& box, const flow::Pyramid& pyr_t,
                                      const flow::Pyramid& pyr_t1, const Foreground& fg_t1,
                                      flow::DenseLK& lk, const MultiTrackerParams& params);

// `detections` with detections[which[k]] replaced by parts[k] (when not empty), each part scored
// by its area; biggest first.
std::vector<Detection> apply_splits(const std::vector<Detection>& detections,
                                    const std::vector<std::size_t>& which,
                                    const std::vector<std::vector<cv::Rect2f>>& parts);

}  // namespace roiflow::tracking
