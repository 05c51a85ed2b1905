// Self-awareness, small and non-rigid targets (issue 20): synthetic scenes where the right
// answer is known — a target that shrinks to ~15 pixels, a thin target whose box is mostly
// background, a target that is hidden (it must be reported lost, not followed on the
// background) and found again, and states that cannot be right (a box as large as the frame).
// Bars are the values measured on this commit's implementation ("measured" comments) with a
// margin.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "eval/otb_score.hpp"
#include "eval/tracking_scene.hpp"
#include "tracking/local_tracker.hpp"
#include "tracking/tracker.hpp"

namespace roiflow::tracking {
namespace {

using eval::center_error;
using eval::iou;

cv::Mat gray_of(const cv::Mat& bgr) {
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  return g;
}

eval::TrackingSceneParams scene_params(cv::Size2f object, double scale_change) {
  eval::TrackingSceneParams p;
  p.size = cv::Size(320, 240);
  p.object = object;
  p.frames = 60;
  p.jump = 0;
  p.scale_change = scale_change;
  return p;
}

// Frame i of `scene` with the target painted over by the background (hidden).
cv::Mat hidden(const eval::TrackingScene& scene, int i) {
  cv::Mat f = scene.render(i);
  const cv::Rect b = cv::Rect(scene.box(i)) & cv::Rect(cv::Point(), f.size());
  const cv::Rect grown =
      cv::Rect(b.x - 3, b.y - 3, b.width + 6, b.height + 6) & cv::Rect(cv::Point(), f.size());
  scene.background()(grown).copyTo(f(grown));
  return f;
}

TEST(LocalTrackerAwareness, FollowsATargetShrinkingToFifteenPixels) {
  // 32 x 30 -> 16 x 15 over the run.
  const eval::TrackingScene scene(scene_params({32.f, 30.f}, -0.49));
  LocalTracker tracker;
  tracker.start({gray_of(scene.render(0)), nullptr}, scene.box(0));
  int lost = 0;
  double min_iou = 1;
  for (int i = 1; i < scene.frames(); ++i) {
    const LocalResult r = tracker.track({gray_of(scene.render(i)), nullptr});
    if (r.lost) {
      ++lost;
      continue;
    }
    min_iou = std::min(min_iou, iou(r.box, scene.box(i)));
  }
  const int last = scene.frames() - 1;
  EXPECT_EQ(lost, 0);
  EXPECT_GT(min_iou, 0.7);
  EXPECT_NEAR(tracker.box().width / scene.box(last).width, 1.0, 0.12);
}

// A thin textured strip crossing a static textured background, its box three times as wide as
// it (two thirds background, as a walking person's box): the median flow of the box is the
// background's, the flow of the pixels that move unlike the background is the target's.
struct ThinScene {
  cv::Mat background;  // 8-bit gray
  cv::Mat strip;       // 8-bit gray, 10 x 40
  static constexpr int kStep = 3;
  cv::Rect strip_at(int i) const { return {60 + kStep * i, 100, strip.cols, strip.rows}; }
  cv::Rect2f box(int i) const {
    const cv::Rect s = strip_at(i);
    return {static_cast<float>(s.x - 10), static_cast<float>(s.y), 30.f,
            static_cast<float>(s.height)};
  }
  cv::Mat render(int i) const {
    cv::Mat f = background.clone();
    strip.copyTo(f(strip_at(i)));
    return f;
  }
};

ThinScene thin_scene() {
  const eval::TrackingScene scene(scene_params({40.f, 30.f}, 0.0));
  ThinScene t;
  t.background = gray_of(scene.background());
  t.strip.create(40, 10, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(t.strip, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(t.strip, t.strip, cv::Size(3, 3), 0.8);
  return t;
}

TEST(LocalTrackerAwareness, FollowsAThinTargetByThePixelsThatMoveWithIt) {
  const ThinScene scene = thin_scene();
  auto run = [&](bool segment) {
    LocalTrackerParams p;
    p.segment = segment;
    p.appearance_weight = 0;  // the flow alone: the appearance correction would pull it along
    // ... and the coarse scale search (3 scales 3 % apart): the finer default one sizes the box of
    // a lost target well enough for the wide appearance search to pull it along too.
    p.scale_steps = 1;
    p.scale_step = 0.03;
    LocalTracker tracker(p);
    tracker.start({scene.render(0), nullptr}, scene.box(0));
    double worst = 0;
    for (int i = 1; i <= 40; ++i) {
      const LocalResult r = tracker.track({scene.render(i), nullptr});
      worst = std::max(worst, r.lost ? 1e9 : center_error(r.box, scene.box(i)));
    }
    return worst;
  };
  // measured: the segmented motion keeps the strip within 2.6 px over 40 frames (120 px); the
  // box's median flow alone lags behind it until the target is lost
  EXPECT_LT(run(true), 3.0);
  EXPECT_GT(run(false), 10.0);
}

TEST(LocalTrackerAwareness, AHiddenTargetIsReportedLostNotFollowedOnTheBackground) {
  const eval::TrackingScene scene(scene_params({56.f, 36.f}, 0.0));
  LocalTracker tracker;
  tracker.start({gray_of(scene.render(0)), nullptr}, scene.box(0));
  for (int i = 1; i < 30; ++i)
    ASSERT_FALSE(tracker.track({gray_of(scene.render(i)), nullptr}).lost) << "frame " << i;
  int lost = 0;
  for (int i = 30; i < 40; ++i) {
    const LocalResult r = tracker.track({gray_of(hidden(scene, i)), nullptr});
    if (r.lost) {
      ++lost;
      EXPECT_NE(r.reason, LostReason::Found);
    }
  }
  // measured: lost from the first hidden frame on
  EXPECT_GE(lost, 8);
  EXPECT_TRUE(tracker.lost());
}

// The target turns: from frame 30 on it shows a texture none of its looks holds, moving as
// before. It is reported lost (the appearance matches no look), and while lost the box follows
// the flow, which still holds, instead of coasting on a decaying velocity.
TEST(LocalTrackerAwareness, ALostTargetWhoseFlowHoldsIsFollowed) {
  eval::TrackingSceneParams sp = scene_params({56.f, 36.f}, 0.0);
  sp.frames = 50;
  const eval::TrackingScene scene(sp);
  cv::Mat other(cv::Size(56, 36), CV_8UC3);
  cv::RNG rng(11);
  rng.fill(other, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(other, other, cv::Size(5, 5), 1.0);
  const auto turned = [&](int i) {
    cv::Mat f = scene.render(i);
    if (i < 30) return f;
    const cv::Rect2f b = scene.box(i);
    const cv::Rect at(static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(b.y)), 56,
                      36);
    const cv::Rect in = at & cv::Rect(cv::Point(), f.size());
    other(in - at.tl()).copyTo(f(in));
    return f;
  };
  for (bool follow : {true, false}) {
    SCOPED_TRACE(follow ? "follow_lost" : "coasting");
    LocalTrackerParams p;
    p.follow_lost = follow;
    LocalTracker tracker(p);
    tracker.start({gray_of(turned(0)), nullptr}, scene.box(0));
    for (int i = 1; i < 30; ++i)
      ASSERT_FALSE(tracker.track({gray_of(turned(i)), nullptr}).lost) << "frame " << i;
    int lost = 0;
    double mean_iou = 0;
    for (int i = 30; i < sp.frames; ++i) {
      const LocalResult r = tracker.track({gray_of(turned(i)), nullptr});
      lost += r.lost ? 1 : 0;
      mean_iou += iou(r.box, scene.box(i)) / (sp.frames - 30);
    }
    // measured: lost on all 20 turned frames; mean IoU 0.93 following, 0.31 coasting
    EXPECT_GE(lost, sp.frames - 30 - 1);
    if (follow) {
      EXPECT_GT(mean_iou, 0.7);
    } else {
      EXPECT_LT(mean_iou, 0.5);
    }
  }
}

TEST(LocalTrackerAwareness, ABoxAsLargeAsTheFrameIsLost) {
  const eval::TrackingScene scene(scene_params({56.f, 36.f}, 0.0));
  LocalTracker tracker;
  const cv::Size s = scene.size();
  tracker.start(
      {gray_of(scene.render(0)), nullptr},
      cv::Rect2f(2.f, 2.f, static_cast<float>(s.width - 4), static_cast<float>(s.height) - 4));
  const LocalResult r = tracker.track({gray_of(scene.render(1)), nullptr});
  EXPECT_TRUE(r.lost);
  EXPECT_EQ(r.reason, LostReason::TooLarge);
}

TEST(LocalTrackerAwareness, VerifyTellsTheTargetFromTheBackground) {
  const eval::TrackingScene scene(scene_params({56.f, 36.f}, 0.0));
  LocalTracker tracker;
  tracker.start({gray_of(scene.render(0)), nullptr}, scene.box(0));
  const cv::Mat frame = gray_of(scene.render(10));
  const cv::Rect2f truth = scene.box(10);
  cv::Rect2f elsewhere = truth;
  elsewhere.y = truth.y < 120 ? truth.y + 100 : truth.y - 100;
  // measured: 0.98 on the target, below 0.4 on the background
  EXPECT_GT(tracker.verify({frame, nullptr}, truth), 0.9);
  EXPECT_LT(tracker.verify({frame, nullptr}, elsewhere), 0.6);
}

TEST(TrackerAwareness, AHiddenTargetIsLostThenFoundAgain) {
  const eval::TrackingScene scene(scene_params({56.f, 36.f}, 0.0));
  TrackerParams p;
  p.init = scene.box(0);
  Tracker tracker(p);
  std::vector<TrackerOutput> outs;
  for (int i = 0; i < scene.frames(); ++i) {
    const cv::Mat bgr = i >= 30 && i < 36 ? hidden(scene, i) : scene.render(i);
    TrackerInput in;
    in.index = i;
    in.image = bgr;
    in.gray = gray_of(bgr);
    outs.push_back(tracker.process(in));
  }
  int lost_hidden = 0;
  for (int i = 30; i < 36; ++i)
    lost_hidden += outs[i].lost ? 1 : 0;
  // measured: every hidden frame lost; found again on the first visible one
  EXPECT_GE(lost_hidden, 5);
  for (int i = 40; i < scene.frames(); ++i) {
    EXPECT_FALSE(outs[i].lost) << "frame " << i;
    EXPECT_GT(iou(outs[i].box, scene.box(i)), 0.7) << "frame " << i;
  }
}

TEST(LocalTrackerAwareness, AFlashOfLightIsBridgedByTheLookAlone) {
  const eval::TrackingScene scene(scene_params({56.f, 36.f}, 0.0));
  const int flash = 20;
  LocalTracker tracker;
  tracker.start({gray_of(scene.render(0)), nullptr}, scene.box(0));
  for (int i = 1; i < 30; ++i) {
    cv::Mat f = scene.render(i);
    // LK's brightness constancy breaks on the flash (and back from it); the looks' NCC does not.
    if (i == flash) f.convertTo(f, -1, 0.3, 0.7 * 128);
    const LocalResult r = tracker.track({gray_of(f), nullptr});
    EXPECT_FALSE(r.lost) << "frame " << i;
    EXPECT_EQ(r.by_look_alone, i == flash || i == flash + 1) << "frame " << i;
    EXPECT_GT(iou(r.box, scene.box(i)), 0.9) << "frame " << i;  // measured >= 0.98
  }
}

}  // namespace
}  // namespace roiflow::tracking
