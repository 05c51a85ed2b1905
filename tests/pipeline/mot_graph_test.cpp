// The multi-object graph (run_mot): the same objects, ids and boxes as the serial MultiTracker
// at any thread count and in-flight bound, every frame once and in order, errors and
// cancellation without a hang, and many objects at once (the TSan selection runs this file).
#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>
#include <vector>

#include "mot_scene.hpp"
#include "pipeline/frame_graph.hpp"
#include "test_util.hpp"
#include "tracking/multi_tracker.hpp"

namespace roiflow::pipeline {
namespace {

using test::MotObject;
using test::MotScene;

FrameSource scene_source(const MotScene& scene, int frames, std::atomic<int>* produced = nullptr) {
  auto next = std::make_shared<int>(0);
  return [&scene, frames, next, produced]() -> std::optional<video::Frame> {
    if (*next >= frames) return std::nullopt;
    video::Frame f;
    f.index = *next;
    f.image = scene.frame(*next);
    cv::cvtColor(f.image, f.gray, cv::COLOR_BGR2GRAY);
    ++*next;
    if (produced != nullptr) produced->store(*next);
    return f;
  };
}

// Many objects on a grid, moving in different directions; some cross.
MotScene busy_scene(int count) {
  std::vector<MotObject> objects;
  for (int i = 0; i < count; ++i) {
    const float x = 30.f + 70.f * static_cast<float>(i % 8),
                y = 30.f + 90.f * static_cast<float>(i / 8);
    const float vx = (i % 3 == 0 ? 2.f : -1.5f), vy = (i % 2 == 0 ? 0.5f : -0.5f);
    objects.push_back({{x, y, 20, 36}, {vx, vy}, 6 + i % 5});
  }
  return MotScene({640, 200 + 90 * ((count - 1) / 8)}, objects);
}

using Frames = std::vector<std::vector<tracking::MotObject>>;

Frames serial(const MotScene& scene, int frames, const tracking::MultiTrackerParams& p) {
  tracking::MultiTracker tracker(p);
  Frames out;
  for (int t = 0; t < frames; ++t) {
    const cv::Mat bgr = scene.frame(t);
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    out.push_back(tracker.process(t, gray, bgr).objects);
  }
  return out;
}

void expect_same(const Frames& a, const Frames& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t t = 0; t < a.size(); ++t) {
    ASSERT_EQ(a[t].size(), b[t].size()) << "frame " << t;
    for (std::size_t i = 0; i < a[t].size(); ++i) {
      EXPECT_EQ(a[t][i].id, b[t][i].id) << "frame " << t;
      EXPECT_EQ(a[t][i].lost, b[t][i].lost) << "frame " << t;
      EXPECT_NEAR(a[t][i].box.x, b[t][i].box.x, 1e-3) << "frame " << t;
      EXPECT_NEAR(a[t][i].box.y, b[t][i].box.y, 1e-3) << "frame " << t;
      EXPECT_NEAR(a[t][i].box.width, b[t][i].box.width, 1e-3) << "frame " << t;
    }
  }
}

TEST(MotGraph, SameResultsAsTheSerialTrackerAtAnyThreadCount) {
  const MotScene scene = busy_scene(16);
  const int frames = 50;
  tracking::MultiTrackerParams p;
  p.tile_rows = 16;  // several tiles per object: the per-frame join is exercised
  const Frames reference = serial(scene, frames, p);
  long long found = 0;
  for (const auto& f : reference)
    for (const auto& o : f)
      found += o.lost ? 0 : 1;
  EXPECT_GT(found, 16 * 8);  // the scene is tracked at all (quality: tests/stages)
  // Every thread count and every in-flight bound, each met once (a full grid repeats the 16-object
  // scene nine times for no new interleaving). ThreadSanitizer, which makes each run cost many
  // seconds, takes the runs that start threads: one bounded and one free.
#ifdef __SANITIZE_THREAD__
  const std::vector<std::pair<int, int>> runs = {{2, 1}, {4, 0}};
#else
  const std::vector<std::pair<int, int>> runs = {{1, 0}, {2, 1}, {2, 3}, {4, 0}};
#endif
  for (const auto& [threads, in_flight] : runs) {
    Frames got;
    long long last_seq = -1;
    MotSink sink{"collect", [&](const MotTrackedFrame& f) {
                   EXPECT_EQ(f.seq, last_seq + 1);  // every frame once, in order
                   last_seq = f.seq;
                   got.push_back(f.output->objects);
                 }};
    GraphOptions o;
    o.threads = threads;
    o.max_in_flight = in_flight;
    const RunReport r = run_mot(scene_source(scene, frames), p, {sink}, o);
    EXPECT_EQ(r.frames, frames);
    if (in_flight > 0) {
      EXPECT_LE(r.max_in_flight, in_flight);
    }
    expect_same(reference, got);
  }
}

TEST(MotGraph, KnownTargetsKeepTheirIds) {
  const MotScene scene({240, 160},
                       {{{20, 40, 24, 40}, {2, 0}, 0}, {{180, 90, 24, 40}, {-2, 0}, 0}});
  tracking::MultiTrackerParams p;
  p.known = {{5, scene.box(0, 0)}, {8, scene.box(1, 0)}};
  p.births = false;
  std::set<long long> ids;
  MotSink sink{"ids", [&](const MotTrackedFrame& f) {
                 for (const auto& o : f.output->objects)
                   ids.insert(o.id);
               }};
  GraphOptions o;
  o.threads = 2;
  run_mot(scene_source(scene, 20), p, {sink}, o);
  EXPECT_EQ(ids, (std::set<long long>{5, 8}));
}

TEST(MotGraph, ASinkErrorEndsTheRunAndIsRethrown) {
  const MotScene scene = busy_scene(4);
  std::atomic<int> produced{0};
  MotSink sink{"fails", [](const MotTrackedFrame& f) {
                 if (f.seq == 10) throw Error("sink failed at 10");
               }};
  GraphOptions o;
  o.threads = 2;
  o.max_in_flight = 4;
  EXPECT_EQ(
      test::error_message([&] { run_mot(scene_source(scene, 200, &produced), {}, {sink}, o); }),
      "sink failed at 10");
  EXPECT_LT(produced.load(), 200);
}

TEST(MotGraph, CancellationStopsReading) {
  const MotScene scene = busy_scene(4);
  std::atomic<bool> cancel{false};
  std::atomic<int> produced{0};
  MotSink sink{"cancel", [&](const MotTrackedFrame& f) {
                 if (f.seq == 5) cancel = true;
               }};
  GraphOptions o;
  o.threads = 2;
  o.cancel = &cancel;
  const RunReport r = run_mot(scene_source(scene, 500, &produced), {}, {sink}, o);
  EXPECT_TRUE(r.cancelled);
  EXPECT_LT(produced.load(), 500);
  EXPECT_EQ(r.frames, produced.load());
}

}  // namespace
}  // namespace roiflow::pipeline
