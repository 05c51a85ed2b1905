// The smallest object the motion detector reports (tracking::smallest_object): min_area
// full-resolution pixels, or min_model_area pixels at the model's resolution where that is less,
// on hand-made foregrounds.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hand_foreground.hpp"
#include "test_util.hpp"
#include "tracking/motion_detector.hpp"

namespace roiflow::tracking {
namespace {

TEST(MotionDetector, TheSmallestObjectIsMinAreaOrMinModelAreaModelPixels) {
  MotionDetectorParams p;                 // min_area 400, min_model_area 100
  EXPECT_EQ(smallest_object(p, 1), 100);  // a frame the model sees whole: 100
  EXPECT_EQ(smallest_object(p, 2), 400);
  EXPECT_EQ(smallest_object(p, 5), 400);  // never more than min_area
  p.min_model_area = 0;
  EXPECT_EQ(smallest_object(p, 1), 400);
  // A far car of 14x9 pixels and a large one in a 320x240 frame the model sees whole: the far
  // car (126 pixels) is an object, as it was not under min_area alone; speckle of 9x9 is not.
  const std::vector<cv::Rect> blobs = {{40, 40, 14, 9}, {150, 120, 40, 30}, {250, 40, 9, 9}};
  MotionDetectorParams d;
  EXPECT_EQ(detect_objects(test::foreground_over(blobs), d).size(), 2u);
  d.min_model_area = 0;
  EXPECT_EQ(detect_objects(test::foreground_over(blobs), d).size(), 1u);
  d.min_model_area = -1;
  EXPECT_NE(test::error_message([&] { d.validate(); }).find("min_model_area"), std::string::npos);
}

}  // namespace
}  // namespace roiflow::tracking
