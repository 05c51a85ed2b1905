// The tracker's annotated video frame: what the tracker saw and decided, drawn on the input.
//
//   using namespace roiflow;
//   stages::TrackerOutput out = tracker.process(input);
//   sink.write(stages::annotate_frame(input.image, out));   // BGR, the size of the input
//
// Drawn on a BGR copy of `image` (8-bit gray or BGR), in this order:
//  - the colour-coded flow (Middlebury, flow::flow_to_color) blended over the image inside
//    `out.region`, when `out.region_flow` holds the flow of that region;
//  - the region's outline;
//  - the target's box when there is one: solid in `local_color` or `global_color` by the mode
//    that produced it, dashed in `lost_color` when the target is lost (the box is then only
//    the prediction), and an arrow from its centre showing the velocity, `arrow_scale` times
//    longer than one frame's motion (a few pixels per frame would otherwise be invisible);
//  - a text line in the top-left corner: "frame N  local|global", followed by "  lost" or
//    "  no target" where that applies. N is 1-based (index + 1), like the track log's frames,
//    so an annotated frame can be looked up in the log.
// Boxes and regions partly or wholly outside the frame are clipped; nothing outside is drawn.
// Lines are drawn without anti-aliasing, so the style's colours appear exactly in the result.
// Throws roiflow::Error for an image that is not 8-bit gray or BGR, a region_flow that is not
// CV_32FC2 of the region's size, or a bad style.
#pragma once

#include <opencv2/core.hpp>

#include "stages/tracker.hpp"

namespace roiflow::stages {

struct AnnotateStyle {
  float flow_alpha = 0.6f;          // weight of the flow colours inside the region, 0..1
  float flow_max_magnitude = -1.f;  // flow magnitude drawn fully saturated; <= 0: the region's
                                    // largest (flow_to_color's rule)
  float arrow_scale = 8.f;          // arrow length in pixels per pixel/frame of velocity, >= 0
  int thickness = 2;                // line thickness in pixels, 1..16
  bool text = true;                 // the "frame N ..." line
  cv::Scalar region_color{255, 255, 255};  // BGR: white
  cv::Scalar local_color{0, 255, 0};       // green
  cv::Scalar global_color{255, 128, 0};    // blue
  cv::Scalar lost_color{0, 0, 255};        // red
  cv::Scalar arrow_color{0, 255, 255};     // yellow
};

cv::Mat annotate_frame(const cv::Mat& image, const TrackerOutput& out,
                       const AnnotateStyle& style = {});

}  // namespace roiflow::stages
