// Shadows that are part of an object: a background model that labels shadows (OpenCV's MOG2:
// a pixel darker than its background by a ratio in [tau, 1) with the background's colour) also
// labels the body of a grey or dark object on a grey background — a car on asphalt, a person in
// dark clothes on pavement — leaving only the parts brighter than the background as foreground.
// A cast shadow lies beside its object and touches it along one side; a body between bright
// parts of an object is surrounded by them. reclaim_enclosed_shadows() takes each connected
// shadow part (8-connected) whose outline (its pixels with a 4-neighbour outside it) lies next
// to the foreground (within one pixel) for at least `share` of its length, and makes it
// foreground.
//
//   cv::Mat labels(240, 320, CV_8U, cv::Scalar(0));       // a MOG2 mask: 0, 127 (shadow), 255
//   labels(cv::Rect(100, 100, 40, 30)).setTo(255);         // the bright outline of a car
//   labels(cv::Rect(104, 104, 32, 22)).setTo(127);         // its grey body, labelled shadow
//   labels(cv::Rect(140, 100, 30, 30)).setTo(127);         // its cast shadow, beside it
//   const int reclaimed = roiflow::tracking::reclaim_enclosed_shadows(labels, 0.7);
//   CV_Assert(reclaimed == 1 && labels.at<uchar>(115, 120) == 255);  // the body: foreground
//   CV_Assert(labels.at<uchar>(115, 160) == 127);                     // the cast shadow: not
#pragma once

#include <opencv2/core.hpp>

namespace roiflow::tracking {

inline constexpr unsigned char kShadowLabel = 127;
inline constexpr unsigned char kForegroundLabel = 255;

// `labels`: CV_8U, 0 background, kShadowLabel shadow, kForegroundLabel foreground; changed in
// place. `share` in (0, 1]. Returns the number of shadow parts made foreground.
int reclaim_enclosed_shadows(cv::Mat& labels, double share);

}  // namespace roiflow::tracking
