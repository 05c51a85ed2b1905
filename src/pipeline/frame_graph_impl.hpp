// Internal to frame_graph.cpp: the message a decoded frame travels in, and the multi-object
// graph's messages and helpers (run_mot: plan -> LK tiles -> collect -> decision).
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "tracking/motion_detector.hpp"
#include "tracking/multi_tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline::frame_graph_impl {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A decoded frame on its way through the pyramid levels.
struct FrameMsg {
  long long seq = 0;
  std::shared_ptr<const video::Frame> frame;
  std::shared_ptr<flow::Pyramid> pyramid;  // filled level by level, then only read
};

// A frame with, in the scene start (tracking::wants_flow), its dense flow back to the previous
// frame (the global treatment's motion); else no flow.
struct StartMsg {
  long long seq = 0;
  FrameMsg frame;
  std::shared_ptr<const flow::FlowResult> back;
};

// A frame after the background refresh and the global treatment.
struct SeenMsg {
  long long seq = 0;
  FrameMsg frame;
  std::shared_ptr<const tracking::Foreground> fg;
  std::shared_ptr<const std::vector<tracking::Detection>> detections;
};
// The decisions at frame t, with what the plan of t+1 needs of frame t.
struct DecidedMsg {
  long long seq = -1;
  std::shared_ptr<const tracking::TrackSet> state;
  std::shared_ptr<const flow::Pyramid> pyramid;
  std::shared_ptr<const tracking::Foreground> fg;
};
// One frame's work between plan and decision.
struct FrameWork {
  SeenMsg now;
  DecidedMsg before;
  std::vector<tracking::ObjectTile> tiles;
  Clock::time_point planned;
};
struct TileMsg {
  std::shared_ptr<const FrameWork> work;
  std::size_t tile = 0;
};
// To the collector: a tile's motion, or (tile < 0) a frame without tiles.
struct CollectMsg {
  std::shared_ptr<const FrameWork> work;
  long long tile = -1;
  tracking::TileMotion motion;
};
struct CollectedMsg {
  std::shared_ptr<const FrameWork> work;
  std::vector<tracking::TileMotion> motions;
};

// Joins a frame's tile motions, which finish in any order: add() returns the frame's motions
// once its last tile (or its header, for a frame without tiles) came in. Serial use only.
class TileCollector {
 public:
  std::optional<CollectedMsg> add(const CollectMsg& m) {
    std::vector<tracking::TileMotion>& motions = pending_[m.work.get()];
    if (m.tile >= 0) motions.push_back(m.motion);
    if (motions.size() != m.work->tiles.size()) return std::nullopt;
    CollectedMsg done{m.work, std::move(motions)};
    pending_.erase(m.work.get());
    return done;
  }

 private:
  std::unordered_map<const FrameWork*, std::vector<tracking::TileMotion>> pending_;
};

// DenseLK objects of one run, for the dense flow nodes and the LK tile tasks: a task borrows one
// (its workspace stays warm: allocating ~10 MB per pair costs page faults) and gives it back. A
// free list, not one per thread: a thread that waits inside OpenCV's TBB loops may start
// another task meanwhile.
class LkPool {
 public:
  explicit LkPool(const flow::LkParams& params) : params_(params) {}
  std::unique_ptr<flow::DenseLK> take() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        std::unique_ptr<flow::DenseLK> lk = std::move(free_.back());
        free_.pop_back();
        return lk;
      }
    }
    return std::make_unique<flow::DenseLK>(params_);
  }
  void give_back(std::unique_ptr<flow::DenseLK> lk) {
    const std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(lk));
  }

 private:
  flow::LkParams params_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<flow::DenseLK>> free_;
};

// The decision at a frame from its tiles' motions: the new state and what the sinks see (each
// object's region is the union of its tiles').
inline std::pair<std::shared_ptr<const tracking::TrackSet>, std::shared_ptr<tracking::MotFrame>>
decide_frame(const CollectedMsg& m, const tracking::MultiTrackerParams& params) {
  const SeenMsg& now = m.work->now;
  bool global_frame = false;
  auto state = std::make_shared<const tracking::TrackSet>(
      tracking::decide(*m.work->before.state, now.frame.frame->index, now.frame.frame->gray.size(),
                       m.motions, *now.fg, *now.detections, params, &global_frame));
  auto out =
      std::make_shared<tracking::MotFrame>(tracking::report_frame(*state, m.motions, global_frame));
  for (tracking::MotObject& o : out->objects) {
    for (const tracking::TileMotion& tm : m.motions) {
      const std::size_t ti = tm.track;
      if (ti < m.work->before.state->tracks.size() && m.work->before.state->tracks[ti].id == o.id)
        o.region |= tm.region;
    }
  }
  return {state, out};
}

}  // namespace roiflow::pipeline::frame_graph_impl
