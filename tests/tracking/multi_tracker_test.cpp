#include "tracking/multi_tracker.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/background_segm.hpp>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "eval/traffic_scene.hpp"
#include "mot_scene.hpp"
#include "test_util.hpp"
#include "tracking/motion_detector.hpp"

namespace roiflow {
namespace {

using test::MotObject;
using test::MotScene;
using tracking::MotFrame;
using tracking::MultiTracker;
using tracking::MultiTrackerParams;

TEST(BoxFilter, LearnsAConstantVelocity) {
  tracking::BoxFilter f = tracking::BoxFilter::start({100, 50, 20, 40});
  for (int t = 1; t <= 20; ++t) {
    f.predict();
    f.correct_box(cv::Rect2f(100.f + 3.f * t, 50.f - 1.f * t, 20, 40));
  }
  EXPECT_NEAR(f.velocity().x, 3.0, 0.1);
  EXPECT_NEAR(f.velocity().y, -1.0, 0.1);
  f.predict();  // the prediction carries the motion on
  EXPECT_NEAR(f.box().x, 100 + 3 * 21, 0.5);
  EXPECT_NEAR(f.box().width, 20, 0.5);
  f.correct_centre({f.box().x + 10 + 5, f.box().y + 20}, 40);  // LK says 5 px further right
  EXPECT_GT(f.box().x, 100 + 3 * 21 + 2);
}

TEST(MergeNested, JoinsNestedAndStackedBoxesOnly) {
  const auto merged = tracking::merge_nested(
      {{10, 10, 20, 40}, {12, 20, 8, 8}, {100, 10, 20, 20}, {100, 34, 20, 20}, {200, 0, 10, 10}},
      0.6, 0.3);
  ASSERT_EQ(merged.size(), 3u);
  EXPECT_EQ(merged[0], cv::Rect2f(10, 10, 20, 40));   // the nested one joined it
  EXPECT_EQ(merged[1], cv::Rect2f(100, 10, 20, 44));  // stacked with a 4 px gap: one object
  EXPECT_EQ(merged[2], cv::Rect2f(200, 0, 10, 10));
  EXPECT_EQ(tracking::merge_nested({{100, 10, 20, 20}, {100, 34, 20, 20}}, 0.6, 0).size(), 2u);
}

TEST(MotionDetector, FindsEveryMovingObject) {
  // They appear once the background model has settled (its first frames learn fast).
  MotScene scene({320, 240}, {{{-40, 40, 20, 50}, {2, 0}, 40},
                              {{230, 130, 30, 30}, {-2, 1}, 40},
                              {{100, 240, 16, 50}, {0, -4.f}, 40}});
  tracking::MotionDetectorParams p;
  p.split_valley = 0.7;
  tracking::MotionDetector detector(p);
  std::vector<tracking::Detection> found;
  tracking::Foreground fg;
  const int last = 55;
  for (int t = 0; t <= last; ++t) {
    fg = detector.observe(scene.frame(t));
    found = tracking::detect_objects(fg, p);
  }
  EXPECT_GT(fg.moving_share(scene.box(0, last)), 0.5);
  EXPECT_LT(fg.moving_share({250, 10, 40, 40}), 0.05);  // static background
  int matched = 0;
  for (int i = 0; i < scene.count(); ++i) {
    for (const tracking::Detection& d : found)
      if (test::box_iou(d.box, scene.box(static_cast<std::size_t>(i), last)) > 0.5) ++matched;
  }
  std::ostringstream boxes;
  for (const tracking::Detection& d : found)
    boxes << " " << d.box;
  EXPECT_EQ(matched, 3) << boxes.str();
}

TEST(DetectObjects, SplitsNeighboursAtTheValleyBetweenThem) {
  tracking::Foreground fg;
  fg.observed = 100;
  fg.frame_size = {200, 100};
  fg.mask = cv::Mat::zeros(100, 200, CV_8U);
  fg.mask(cv::Rect(20, 20, 16, 50)).setTo(255);  // two objects 3 px apart: closing joins them
  fg.mask(cv::Rect(39, 22, 16, 50)).setTo(255);
  fg.mask(cv::Rect(120, 20, 40, 30)).setTo(255);  // one wide object: no valley, no split
  cv::integral(fg.mask / 255, fg.integral, CV_32S);
  tracking::MotionDetectorParams p;
  p.work_width = 0;
  p.split_valley = 0.7;
  std::vector<tracking::Detection> found = tracking::detect_objects(fg, p);
  std::sort(
      found.begin(), found.end(),
      [](const tracking::Detection& a, const tracking::Detection& b) { return a.box.x < b.box.x; });
  std::ostringstream got;
  for (const auto& d : found)
    got << " " << d.box;
  ASSERT_EQ(found.size(), 3u) << got.str();
  EXPECT_EQ(found[0].box, cv::Rect2f(20, 20, 16, 50));
  EXPECT_EQ(found[1].box, cv::Rect2f(36, 22, 19, 50));  // from the valley on
  EXPECT_EQ(found[2].box, cv::Rect2f(120, 20, 40, 30));
  p.split_valley = 0;
  EXPECT_EQ(tracking::detect_objects(fg, p).size(), 2u);
}

TEST(DetectObjects, AHoleInsideAnObjectIsNoValley) {
  // A vehicle's window the background model misses: its columns hold fewer moving pixels, but
  // the object spans them top to bottom (a valley of the pixel count, not a gap).
  tracking::Foreground fg;
  fg.observed = 100;
  fg.frame_size = {200, 100};
  fg.mask = cv::Mat::zeros(100, 200, CV_8U);
  fg.mask(cv::Rect(20, 30, 70, 30)).setTo(255);
  fg.mask(cv::Rect(60, 35, 12, 20)).setTo(0);  // the hole: 1/3 of its columns' pixels left
  cv::integral(fg.mask / 255, fg.integral, CV_32S);
  tracking::MotionDetectorParams p;
  p.work_width = 0;
  p.split_valley = 0.7;
  const std::vector<tracking::Detection> found = tracking::detect_objects(fg, p);
  std::ostringstream got;
  for (const auto& d : found)
    got << " " << d.box;
  ASSERT_EQ(found.size(), 1u) << got.str();
  EXPECT_EQ(found[0].box, cv::Rect2f(20, 30, 70, 30));
}

// Claims `threads` and runs each chunk for_range is given on a thread of its own: real parallel
// bands.
class ThreadsExecutor final : public Executor {
 public:
  explicit ThreadsExecutor(int threads) : threads_(threads) {}
  void for_range(int begin, int end, int grain,
                 const std::function<void(int, int)>& body) const override {
    std::vector<std::thread> pool;
    for (const auto& [b, e] : test::chunks_of(begin, end, grain))
      pool.emplace_back([&body, b = b, e = e] { body(b, e); });
    for (std::thread& t : pool)
      t.join();
  }
  int concurrency() const override { return threads_; }

 private:
  int threads_;
};

TEST(MotionDetector, BandsOfRowsMaskAsOneModelOverTheFrame) {
  // Given a parallel executor, the model learns in bands of rows at once; MOG2 models each pixel
  // alone, so the mask is the one a single model over the whole frame gives, with any executor.
  // The comparison needs the detector's own steps off (ghosts, scene start, opening) and the
  // frame at its working size.
  MotScene scene({320, 240}, {{{-40, 40, 20, 50}, {3, 0}, 40}, {{230, 130, 30, 30}, {-2, 1}, 40}});
  tracking::MotionDetectorParams p;
  p.ghost_frames = 0;
  p.start_frames = 0;
  p.open = 0;
  p.work_width = 320;
  const SerialExecutor serial;
  const ThreadsExecutor two(2), four(4), many(16);
  for (const Executor* executor :
       std::vector<const Executor*>{nullptr, &serial, &two, &four, &many}) {
    tracking::MotionDetector detector(p);
    cv::Ptr<cv::BackgroundSubtractorMOG2> one =
        cv::createBackgroundSubtractorMOG2(p.history, p.var_threshold, p.shadows);
    one->setShadowThreshold(p.shadow_threshold);
    one->setBackgroundRatio(p.background_ratio);
    const int threads = executor != nullptr ? executor->concurrency() : 0;
    int moving = 0;
    for (int t = 0; t < 60; ++t) {  // the objects enter at frame 40
      const cv::Mat frame = scene.frame(t);
      const tracking::Foreground fg = detector.observe(frame, nullptr, executor);
      cv::Mat raw, mask;
      one->apply(frame, raw);
      cv::threshold(raw, mask, 200, 255, cv::THRESH_BINARY);
      ASSERT_EQ(cv::countNonZero(fg.mask != mask), 0) << "frame " << t << ", threads " << threads;
      moving += cv::countNonZero(mask);
    }
    EXPECT_GT(moving, 1000);  // the comparison saw moving pixels
  }
}
// Object 0 stands still from the first frame, so that the background model learns it as
// background; at frame 30 object 1 takes its place and drives away. Where object 0 stood then
// turns into foreground for a while (a ghost), though nothing changes there.
MotScene ghost_scene() {
  return MotScene({240, 160}, {{{20, 60, 24, 40}, {0, 0}, 0, 29}, {{20, 60, 24, 40}, {4, 0}, 30}});
}

TEST(MotionDetector, TellsAGhostFromAMovingObject) {
  const MotScene scene = ghost_scene();
  tracking::MotionDetectorParams p;
  p.ghost_frames = 0;  // the model's own foreground, ghost and all
  tracking::MotionDetector detector(p);
  tracking::Foreground fg;
  const int last = 46;
  for (int t = 0; t <= last; ++t)
    fg = detector.observe(scene.frame(t));
  const cv::Rect2f ghost = scene.box(0, 0), now = scene.box(1, last);
  ASSERT_EQ((ghost & now).area(), 0.f);
  EXPECT_GT(fg.moving_share(ghost), 0.3);
  EXPECT_LT(fg.changed_share(ghost), 0.01);
  EXPECT_GT(fg.moving_share(now), 0.5);
  EXPECT_GT(fg.changed_share(now), 0.1);
  EXPECT_LT(fg.changed_share({150, 10, 40, 40}), 0.01);  // static background
  EXPECT_EQ(fg.absorbed, 0);
}

TEST(MotionDetector, AbsorbsAGhostIntoTheBackgroundAtOnce) {
  // The same scene with ghost absorption (the default): once the object has left the place it
  // stood in while the model learnt it, that place (unchanged for ghost_frames frames) is
  // background again, long before the model would learn it; the object that drives away stays
  // foreground, every frame.
  const MotScene scene = ghost_scene();
  tracking::MotionDetectorParams p;
  ASSERT_GT(p.ghost_frames, 0);
  tracking::MotionDetector detector(p);
  tracking::Foreground fg;
  const cv::Rect2f ghost = scene.box(0, 0);
  const int left = 30;  // the object that stood there is gone, the other drives on
  const int last = left + p.change_frames + p.ghost_frames + 2;
  for (int t = 0; t <= last; ++t) {
    fg = detector.observe(scene.frame(t));
    if (t >= left + 2) {
      EXPECT_GT(fg.moving_share(scene.box(1, t)), 0.5) << "frame " << t;
    }
  }
  EXPECT_GT(fg.absorbed, 0);
  EXPECT_LT(fg.moving_share(ghost), 0.05);
  // Something new standing there later is foreground again: a pixel is absorbed at its gray
  // level and comes back when that changes.
  cv::Mat frame = scene.frame(last + 1);
  cv::rectangle(frame, cv::Rect(ghost), cv::Scalar(255, 255, 255), cv::FILLED);
  fg = detector.observe(frame);
  EXPECT_GT(fg.moving_share(ghost), 0.5);
}

TEST(MotionDetector, TheSceneStartFindsVehiclesMovingInTheFirstFrame) {
  // The model learns the first frame as background, the vehicles driving in it included: without
  // the scene start a vehicle's body over its own first place is background (a hole that cuts it
  // into slices) and the place it left is foreground (a ghost joined to it). With it, the motion
  // of each pixel's neighbourhood decides in the first frames: more vehicles are found whole
  // (IoU >= 0.5 with their exact boxes) over frames 6..20, and fewer moving pixels lie off every
  // vehicle (a ghost is absorbed; the fill stays inside the foreground's parts).
  const eval::TrafficScene scene({.size = {640, 480}, .frames = 21, .objects = 8});
  int matched[2] = {0, 0};
  long long stray[2] = {0, 0};  // moving pixels (model resolution) off every vehicle
  for (const int start : {0, 30}) {
    tracking::MotionDetectorParams p;
    p.start_frames = start;
    tracking::MotionDetector detector(p);
    for (int t = 0; t <= 20; ++t) {
      const tracking::Foreground fg = detector.observe(scene.render(t));
      if (t < 6) continue;
      const std::vector<tracking::Detection> found = tracking::detect_objects(fg, p);
      cv::Mat off(fg.mask.size(), CV_8U, cv::Scalar(255));
      for (const eval::MotBox& truth : scene.boxes(t)) {
        const double s = fg.scale;
        off(cv::Rect(cv::Point(static_cast<int>((truth.box.x - 3) / s),
                               static_cast<int>((truth.box.y - 3) / s)),
                     cv::Point(static_cast<int>((truth.box.br().x + 2) / s) + 1,
                               static_cast<int>((truth.box.br().y + 2) / s) + 1)) &
            cv::Rect(0, 0, off.cols, off.rows))
            .setTo(0);
      }
      stray[start > 0 ? 1 : 0] += cv::countNonZero(fg.mask & off);
      for (const eval::MotBox& truth : scene.boxes(t)) {
        const cv::Rect2f gt(
            static_cast<float>(truth.box.x - 1), static_cast<float>(truth.box.y - 1),
            static_cast<float>(truth.box.width), static_cast<float>(truth.box.height));
        double best = 0;
        for (const tracking::Detection& d : found)
          best = std::max(best, test::box_iou(d.box, gt));
        if (best >= 0.5) ++matched[start > 0 ? 1 : 0];
      }
    }
  }
  EXPECT_GE(matched[1], matched[0] + 6);  // of about 120 vehicle boxes
  EXPECT_LT(stray[1], stray[0]);          // the ghosts absorbed, nothing filled off the vehicles
}

TEST(MotionDetector, TheSceneStartAbsorbsNoPartOfAMovingBody) {
  // A wide object driving left 2.5 px a frame, its texture weak in places: over `change_frames`
  // (4) frames it moved 10 px, and parts of its body changed by more than a still
  // neighbourhood's bound allows but less than the camera-noise guard. Only the bound proves
  // stillness: no pixel of the moving body is absorbed as uncovered background, and the
  // foreground keeps the box as whole as without the scene start.
  MotScene scene({320, 240}, {{{250, 100, 60, 22}, {-2.5f, 0}, 8}});
  double share[2] = {0, 0};
  long long absorbed = 0;  // pixels absorbed inside the body
  for (const int start : {0, 30}) {
    tracking::MotionDetectorParams p;
    p.start_frames = start;
    p.ghost_frames = 0;  // the scene start's absorption alone
    tracking::MotionDetector detector(p);
    for (int t = 0; t <= 30; ++t) {
      const tracking::Foreground fg = detector.observe(scene.frame(t));
      if (t < 12) continue;
      share[start > 0 ? 1 : 0] += fg.moving_share(scene.box(0, t)) / 19;
      if (start > 0) absorbed = std::max(absorbed, fg.absorbed);
    }
  }
  EXPECT_EQ(absorbed, 0);
  EXPECT_GT(share[1], 0.9);
  EXPECT_GE(share[1], share[0] - 0.01);
}

TEST(MotionDetector, RejectsBadParamsAndSizeChanges) {
  tracking::MotionDetectorParams p;
  p.min_area = 0;
  EXPECT_NE(test::error_message([&] { tracking::MotionDetector d(p); }).find("min_area"),
            std::string::npos);
  tracking::MotionDetector d;
  d.observe(cv::Mat(100, 100, CV_8UC3, cv::Scalar::all(0)));
  EXPECT_NE(test::error_message([&] { d.observe(cv::Mat(50, 100, CV_8UC3)); }).find("size"),
            std::string::npos);
}

// Runs the tracker over a scene; per frame, the reported (found) objects by id.
std::vector<std::map<long long, cv::Rect2f>> run(const MotScene& scene, int frames,
                                                 const MultiTrackerParams& params = {},
                                                 MotFrame* last = nullptr) {
  MultiTracker tracker(params);
  std::vector<std::map<long long, cv::Rect2f>> out;
  for (int t = 0; t < frames; ++t) {
    const cv::Mat bgr = scene.frame(t);
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    const MotFrame f = tracker.process(t, gray, bgr);
    std::map<long long, cv::Rect2f> found;
    for (const tracking::MotObject& o : f.objects)
      if (!o.lost) found[o.id] = o.box;
    out.push_back(found);
    if (last != nullptr) *last = f;
  }
  return out;
}

// For each scene object, the ids of the boxes that matched it best (IoU > 0.5) and the share of
// its frames (from `from` on, while it is in view) where one did.
struct Coverage {
  std::set<long long> ids;
  double covered = 0;
};
std::vector<Coverage> coverage(const MotScene& scene,
                               const std::vector<std::map<long long, cv::Rect2f>>& found,
                               int from) {
  std::vector<Coverage> out(static_cast<std::size_t>(scene.count()));
  const cv::Rect2f frame(0, 0, static_cast<float>(scene.size().width),
                         static_cast<float>(scene.size().height));
  for (std::size_t i = 0; i < out.size(); ++i) {
    int frames = 0, good = 0;
    for (int t = from; t < static_cast<int>(found.size()); ++t) {
      const cv::Rect2f truth = scene.box(i, t);
      if (truth.area() <= 0 || (truth & frame).area() < 0.9 * truth.area()) continue;
      bool hidden = false;  // overlapping another: either may be the one in front
      for (std::size_t j = 0; j < out.size(); ++j)
        if (j != i && (scene.box(j, t) & truth).area() > 0) hidden = true;
      if (hidden) continue;
      ++frames;
      double best = 0.5;
      long long best_id = 0;
      for (const auto& [id, box] : found[static_cast<std::size_t>(t)]) {
        const double o = test::box_iou(box, truth);
        if (o > best) best = o, best_id = id;
      }
      if (best_id != 0) out[i].ids.insert(best_id);
      good += best_id != 0 ? 1 : 0;
    }
    out[i].covered = frames > 0 ? static_cast<double>(good) / frames : 0;
  }
  return out;
}

TEST(MultiTracker, FollowsEveryObjectWithOneIdEach) {
  MotScene scene({320, 240}, {{{20, 30, 20, 44}, {2.5f, 0.5f}, 8},
                              {{250, 150, 26, 26}, {-2, -0.5f}, 8},
                              {{140, 100, 18, 40}, {0.5f, 1.5f}, 20}});  // born later
  MotFrame last;
  const auto found = run(scene, 70, {}, &last);
  const std::vector<Coverage> c = coverage(scene, found, 35);
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c[i].ids.size(), 1u) << "object " << i;
    EXPECT_GT(c[i].covered, 0.9) << "object " << i;
  }
  EXPECT_EQ(last.born, 3);
  EXPECT_GE(last.global_activations, 1);
}

// Two objects, each followed over 80 % of its frames under one id of its own.
void expect_two_kept_apart(const std::vector<Coverage>& c) {
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c[i].ids.size(), 1u) << "object " << i;
    EXPECT_GT(c[i].covered, 0.8) << "object " << i;
  }
  ASSERT_FALSE(c[0].ids.empty());
  ASSERT_FALSE(c[1].ids.empty());
  EXPECT_NE(*c[0].ids.begin(), *c[1].ids.begin());
}

TEST(MultiTracker, KeepsIdsThroughACrossing) {
  // Two objects of one size walk into each other and through: the blobs merge for several
  // frames, where LK keeps them apart.
  MotScene scene({320, 200}, {{{40, 80, 22, 46}, {3, 0}, 8}, {{258, 84, 22, 46}, {-3, 0}, 8}});
  const auto found = run(scene, 80);
  expect_two_kept_apart(coverage(scene, found, 30));
}

TEST(MultiTracker, KeepsEachObjectThroughAPerpendicularCrossing) {
  // A tall object driving up and a wide one driving left across it, in front of it: while they
  // overlap, the shared pixels move with the one in front. Each object is measured by its own
  // pixels only (not those inside the other's box), so the tall one's box is not dragged
  // sideways with the wide one and both keep their ids.
  MotScene scene({320, 240},
                 {{{150, 150, 24, 50}, {0, -1.5f}, 8}, {{250, 100, 60, 22}, {-2.5f, 0}, 8}});
  const auto found = run(scene, 100);
  expect_two_kept_apart(coverage(scene, found, 25));
}

TEST(MultiTracker, ReportsNothingOnAStaticSceneAndEndsObjectsThatLeave) {
  MotScene still({200, 150}, {});
  for (const auto& f : run(still, 40))
    EXPECT_TRUE(f.empty());
  // An object crossing out of the right edge ends; nothing is reported at the border after.
  MotScene leaving({200, 150}, {{{100, 50, 20, 40}, {4, 0}, 8}});
  MotFrame last;
  const auto found = run(leaving, 60, {}, &last);
  EXPECT_GE(last.born, 1);
  EXPECT_EQ(last.ended, last.born);  // everything it found has ended
  for (int t = 40; t < 60; ++t)
    EXPECT_TRUE(found[static_cast<std::size_t>(t)].empty()) << t;
  // Every reported box is at least min_side wide and mostly inside the frame.
  for (const auto& f : found) {
    for (const auto& [id, box] : f) {
      EXPECT_GE(box.width, 8);
      EXPECT_GE((box & cv::Rect2f(0, 0, 200, 150)).area(), 0.5 * box.area());
    }
  }
}

TEST(MultiTracker, ObjectThatStopsEndsAndIsNotReportedOnEmptyBackground) {
  // Moves for a while, then stands still: once the background model has learnt it, no moving
  // pixels are left in its box and it must not stay reported as found there.
  MotScene scene({200, 150}, {{{30, 50, 20, 40}, {3, 0}, 8, 30}});  // gone after frame 30
  MultiTrackerParams p;
  const auto found = run(scene, 90, p);
  for (int t = 31 + p.max_lost + 2; t < 90; ++t)
    EXPECT_TRUE(found[static_cast<std::size_t>(t)].empty()) << "frame " << t;
}

TEST(MultiTracker, StartsNoObjectOnAGhost) {
  const MotScene scene = ghost_scene();
  const cv::Rect2f ghost = scene.box(0, 0);
  const auto found = run(scene, 75);
  for (int t = 42; t < 75; ++t) {
    for (const auto& [id, box] : found[static_cast<std::size_t>(t)])
      EXPECT_LT(test::box_iou(box, ghost), 0.2) << "frame " << t << " object " << id << " " << box;
  }
  const std::vector<Coverage> c = coverage(scene, found, 45);
  EXPECT_GT(c[1].covered, 0.8);  // the object that drives away is found
}

TEST(Decide, EndsAFragmentInsideAnOlderObject) {
  // A slice the blob split once cut off a vehicle, followed as an object of its own inside the
  // vehicle's box: it ends after 3 frames; an object as small beside the vehicle stays.
  MultiTrackerParams p;
  tracking::TrackSet s;
  s.frame = 10;
  s.size = {320, 240};
  s.next_id = 4;
  const cv::Rect2f vehicle(100, 100, 80, 36), slice(150, 102, 16, 32), beside(250, 100, 16, 32);
  const std::pair<long long, cv::Rect2f> objects[] = {{1, vehicle}, {2, slice}, {3, beside}};
  for (const auto& [id, box] : objects) {
    tracking::Track t;
    t.id = id;
    t.box = box;
    t.filter = tracking::BoxFilter::start(box);
    t.age = id == 1 ? 30 : 5;
    s.tracks.push_back(t);
  }
  const std::vector<tracking::Detection> found = {{vehicle, {140, 118}, vehicle.area()},
                                                  {beside, {258, 116}, beside.area()}};
  const tracking::Foreground none;
  for (int k = 1; k <= 3; ++k) {
    s = tracking::decide(s, 10 + k, s.size, {}, none, found, p);
    std::set<long long> ids;
    for (const tracking::Track& t : s.tracks)
      ids.insert(t.id);
    EXPECT_EQ(ids.count(1), 1u) << "frame " << k;
    EXPECT_EQ(ids.count(3), 1u) << "frame " << k;
    EXPECT_EQ(ids.count(2), k < 3 ? 1u : 0u) << "frame " << k;
  }
}

// A track set of confirmed objects `boxes` (ids 1, 2, ...), decided up to frame 10.
// A 320x240 foreground whose every pixel moves (mask and changed-pixel integral all set).
tracking::Foreground moving_everywhere() {
  tracking::Foreground fg;
  fg.scale = 1;
  fg.frame_size = {320, 240};
  fg.mask = cv::Mat(240, 320, CV_8U, cv::Scalar(255));
  cv::integral(cv::Mat(240, 320, CV_8U, cv::Scalar(1)), fg.integral, CV_32S);
  return fg;
}

tracking::TrackSet tracks_of(const std::vector<cv::Rect2f>& boxes) {
  tracking::TrackSet s;
  s.frame = 10;
  s.size = {320, 240};
  s.next_id = static_cast<long long>(boxes.size()) + 1;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    tracking::Track t;
    t.id = static_cast<long long>(i) + 1;
    t.box = boxes[i];
    t.filter = tracking::BoxFilter::start(boxes[i]);
    t.age = 10;
    s.tracks.push_back(t);
  }
  return s;
}

TEST(Decide, ABlobMostlyOneObjectIsItsDetection) {
  // A blob over two objects is a merge (LK alone moves them), unless one of them is most of it
  // (IoU >= merge_own): a slice or a small object passing in front of a vehicle. That one takes
  // the detection and its box follows it.
  MultiTrackerParams p;
  const cv::Rect2f vehicle(100, 100, 70, 36), slice(172, 104, 12, 28);
  const cv::Rect2f blob(104, 100, 82, 36);  // the vehicle 4 px on, with the slice
  ASSERT_GE(test::box_iou(vehicle, blob), p.merge_own);
  const tracking::Foreground none;
  tracking::TrackSet s = tracks_of({vehicle, slice});
  s = tracking::decide(s, 11, s.size, {}, none, {{blob, {145, 118}, blob.area()}}, p);
  ASSERT_EQ(s.tracks.size(), 2u);
  EXPECT_GT(s.tracks[0].box.x, vehicle.x + 2);  // corrected by the blob
  EXPECT_GT(s.tracks[0].box.width, vehicle.width + 2);
  EXPECT_EQ(s.tracks[0].lost, 0);
  EXPECT_GT(s.tracks[1].lost, 0);  // the slice got nothing
  // Two objects of a size side by side in one blob: a merge, the blob corrects neither.
  const cv::Rect2f left(100, 100, 40, 36), right(142, 100, 40, 36), both(100, 100, 82, 36);
  ASSERT_LT(test::box_iou(left, both), p.merge_own);
  s = tracking::decide(tracks_of({left, right}), 11, {320, 240}, {}, none,
                       {{both, {141, 118}, both.area()}}, p);
  ASSERT_EQ(s.tracks.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_GT(s.tracks[i].lost, 0) << i;
    EXPECT_NEAR(s.tracks[i].box.width, 40, 0.5) << i;
  }
}

TEST(Decide, InAMergeTheSizeSpeedFades) {
  // An object whose box was growing (entering the frame), then in a merge (one blob over it and
  // its neighbour): LK alone measures it, which gives no size, so the size's speed fades by
  // lk_size_decay a frame instead of growing the box on and on.
  MultiTrackerParams p;
  const tracking::Foreground fg = moving_everywhere();
  const cv::Rect2f left(100, 100, 40, 36), right(142, 100, 40, 36), both(100, 100, 82, 36);
  tracking::TrackSet s = tracks_of({left, right});
  s.tracks[0].filter.x[6] = 2;  // width growing 2 px a frame
  std::vector<tracking::TileMotion> m(2);
  for (std::size_t i = 0; i < 2; ++i) {
    m[i].track = i;
    m[i].sampled = 40;
    m[i].moves.assign(40, cv::Point2f(0, 0));
  }
  const std::vector<tracking::Detection> blob = {{both, {141, 118}, both.area()}};
  for (int k = 1; k <= 20; ++k) {
    s = tracking::decide(s, 10 + k, s.size, m, fg, blob, p);
    ASSERT_EQ(s.tracks.size(), 2u);
    EXPECT_EQ(s.tracks[0].lost, 0) << k;  // measured by LK
    EXPECT_NEAR(s.tracks[0].filter.x[6], 2 * std::pow(p.lk_size_decay, k), 1e-6) << k;
  }
  // The sum of a fading speed: 2 * 0.9 / (1 - 0.9) = 18 px at most, not 2 px a frame for ever.
  EXPECT_LT(s.tracks[0].box.width, 40 + 2 / (1 - p.lk_size_decay) + 1);
}

TEST(Decide, AYoungObjectWhosePixelsStandStillIsAGhost) {
  // Three objects whose boxes hold moving pixels: LK finds the pixels of the first two standing
  // still, those of the third moving. The young one standing still (a birth on the uncovered
  // background behind an object) ends after parked_frames; the older one standing still (it may
  // have stopped) and the young one moving stay.
  MultiTrackerParams p;
  const tracking::Foreground fg = moving_everywhere();
  tracking::TrackSet s =
      tracks_of({{20, 20, 40, 36}, {120, 20, 40, 36}, {220, 120, 40, 36}});  // ids 1, 2, 3
  s.tracks[0].age = 2;
  s.tracks[1].age = 40;
  s.tracks[2].age = 2;
  s.tracks[2].filter = tracking::BoxFilter::start(s.tracks[2].box, {1, 0});
  std::vector<tracking::TileMotion> m(3);
  for (std::size_t i = 0; i < 3; ++i) {
    m[i].track = i;
    m[i].sampled = 40;
    m[i].moves.assign(40, i == 2 ? cv::Point2f(1, 0) : cv::Point2f(0, 0));
  }
  for (int k = 1; k <= p.parked_frames; ++k) {
    s = tracking::decide(s, 10 + k, s.size, m, fg, {}, p);
    std::set<long long> ids;
    for (const tracking::Track& t : s.tracks)
      ids.insert(t.id);
    EXPECT_EQ(ids.count(1), k < p.parked_frames ? 1u : 0u) << k;
    EXPECT_EQ(ids.count(2), 1u) << k;
    EXPECT_EQ(ids.count(3), 1u) << k;
    for (std::size_t i = 0; i < s.tracks.size(); ++i)  // the motions' indices follow the set
      m[i].track = i,
      m[i].moves.assign(40, s.tracks[i].id == 3 ? cv::Point2f(1, 0) : cv::Point2f(0, 0));
  }
}

TEST(MultiTracker, FollowsKnownTargetsWithTheirIds) {
  MotScene scene({240, 160}, {{{20, 40, 24, 40}, {2, 0}, 0}, {{180, 90, 24, 40}, {-2, 0}, 0}});
  MultiTrackerParams p;
  p.known = {{7, scene.box(0, 0)}, {9, scene.box(1, 0)}};
  p.births = false;
  const auto found = run(scene, 40, p);
  for (int t = 0; t < 40; t += 5) {
    const auto& f = found[static_cast<std::size_t>(t)];
    ASSERT_EQ(f.count(7), 1u) << t;
    ASSERT_EQ(f.count(9), 1u) << t;
    EXPECT_GT(test::box_iou(f.at(7), scene.box(0, t)), 0.6)
        << t << " " << f.at(7) << " " << scene.box(0, t);
    EXPECT_GT(test::box_iou(f.at(9), scene.box(1, t)), 0.6) << t;
  }
}

TEST(KnownTargets, ParsesAndRejects) {
  const auto k = tracking::parse_known_targets("# id,x,y,w,h\n3,1,2,30,40\n\n5,10.5,0,8,9\n", "t");
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[0].id, 3);
  EXPECT_EQ(k[1].box, cv::Rect2f(10.5f, 0, 8, 9));
  const std::pair<const char*, const char*> bad[] = {
      {"1,2,3,4\n", "t:1: expected 5 fields"},
      {"0,1,2,3,4\n", "t:1: id '0'"},
      {"1,1,2,3,nan\n", "t:1: h 'nan'"},
      {"1,1,2,0,4\n", "t:1: the box needs a positive"},
      {"1,1,2,3,4\n1,5,6,7,8\n", "t:2: id 1 given twice"},
      {"# nothing\n", "no target"}};
  for (const auto& [text, expected] : bad) {
    const std::string m = test::error_message([&] { tracking::parse_known_targets(text, "t"); });
    EXPECT_NE(m.find(expected), std::string::npos) << m;
  }
}

TEST(MultiTrackerParams, RejectsBadValues) {
  MultiTrackerParams p;
  p.min_side = 0;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("min_side"), std::string::npos);
  p = {};
  p.merge_own = 0;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("merge_own"), std::string::npos);
  p = {};
  p.lk_size_decay = 1.5;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("lk_size_decay"), std::string::npos);
  p = {};
  p.detector.ghost_frames = -1;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("ghost_frames"), std::string::npos);
  p.detector.ghost_frames = 8;
  p.detector.start_frames = -1;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("start_frames"), std::string::npos);
  p = {};
  p.parked_frames = 0;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("parked_frames"), std::string::npos);
  p = {};
  p.parked_motion = -1;
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("parked_motion"), std::string::npos);
  p = {};
  p.known = {{1, {0, 0, 10, 10}}, {1, {5, 5, 10, 10}}};
  EXPECT_NE(test::error_message([&] { p.validate(); }).find("twice"), std::string::npos);
}

}  // namespace
}  // namespace roiflow
