// BoxTracker: every tracker answers its initial box on the first frame and follows a smooth
// synthetic vehicle; unknown names and gray pictures.
#include "tracking/box_tracker.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "eval/otb_score.hpp"
#include "eval/tracking_scene.hpp"
#include "test_util.hpp"

namespace roiflow::tracking {
namespace {

video::Frame box_frame(const cv::Mat& bgr, long long index) {
  video::Frame f;
  f.index = index;
  f.image = bgr;
  cv::cvtColor(bgr, f.gray, cv::COLOR_BGR2GRAY);
  return f;
}

TEST(BoxTrackerTest, EveryTrackerStartsOnItsBoxAndFollowsASmoothTarget) {
  eval::TrackingSceneParams params;
  params.size = {160, 120};
  params.frames = 80;  // a slow crossing: about 1.5 px per frame
  params.object = {36.f, 24.f};
  params.jump = 0;
  const eval::TrackingScene scene(params);
  for (const std::string& name : box_tracker_names()) {
    SCOPED_TRACE(name);
    std::unique_ptr<BoxTracker> t = make_box_tracker(name);
    const video::Frame first = box_frame(scene.render(0), 0);
    const BoxUpdate start = t->start(first, bgr_picture(first), scene.box(0));
    EXPECT_FALSE(start.lost);
    EXPECT_GT(eval::iou(start.box, scene.box(0)), 0.9);
    double iou_sum = 0;
    const int frames = 16;
    for (int i = 1; i < frames; ++i) {
      const video::Frame f = box_frame(scene.render(i), i);
      iou_sum += eval::iou(t->next(f, bgr_picture(f)).box, scene.box(i));
    }
    // A slowly moving, well-textured target on a static background: every tracker follows it
    // closely.
    EXPECT_GT(iou_sum / (frames - 1), 0.7) << iou_sum / (frames - 1);
  }
}

TEST(BoxTrackerTest, UnknownNamesThrowListingTheKnownOnes) {
  EXPECT_NE(test::error_message([] {
              make_box_tracker("boosting");
            }).find("unknown tracker 'boosting' (known: roiflow, csrt, kcf, mosse, medianflow)"),
            std::string::npos);
}

TEST(BoxTrackerTest, GrayPicturesBecomeBgr) {
  video::Frame f;
  f.gray = cv::Mat(8, 10, CV_8UC1, cv::Scalar(77));
  f.image = f.gray;
  const cv::Mat bgr = bgr_picture(f);
  EXPECT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(3, 4), cv::Vec3b(77, 77, 77));
  video::Frame colour = box_frame(cv::Mat(8, 10, CV_8UC3, cv::Scalar(1, 2, 3)), 0);
  EXPECT_EQ(bgr_picture(colour).data, colour.image.data);  // no copy
}

}  // namespace
}  // namespace roiflow::tracking
