// The tracker's annotated video frame: what it saw and decided, drawn on a BGR copy of the
// input: the colour-coded flow of the local region, the region's outline, the target's box
// (solid by the mode that produced it, dashed when lost), its velocity and a status line.
// The annotation is a plain record, so drawing needs no tracker (docs/REPORTS.md has the
// details).
//
//   roiflow::report::TrackAnnotation a;  // what the tracker decided for a frame
//   a.has_target = true;
//   a.box = {70, 51, 107, 87};
//   a.velocity = {2.f, 0.f};
//   const cv::Mat drawn = roiflow::report::annotate_frame(frame_t, a);  // CV_8UC3
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::report {

// One frame's tracking result, as annotate_frame draws it.
struct TrackAnnotation {
  long long index = 0;      // 0-based frame index (shown 1-based, like the track log)
  bool has_target = false;  // false until the target is known
  cv::Rect2f box;           // the target's box (when has_target)
  cv::Point2f velocity;     // pixels per frame
  bool global = true;       // the box came from the global treatment (else the local one)
  bool lost = false;        // the target was not found (box = prediction)
  cv::Rect region;          // where LK ran (empty when it did not)
  cv::Mat region_flow;      // CV_32FC2 flow over `region`, or empty
};

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

cv::Mat annotate_frame(const cv::Mat& image, const TrackAnnotation& out,
                       const AnnotateStyle& style = {});

// Every object of a multi-object frame (tracking::MotFrame, filled by the pipeline):
//
//   roiflow::report::ObjectsAnnotation a;
//   a.objects.push_back({3, {70, 51, 30, 80}, {2.f, 0.f}, false, {}});
//   cv::Mat bgr = roiflow::report::annotate_objects(cv::Mat(240, 320, CV_8UC1, 128), a);
//
// Each id gets its own colour (id_color): its box (solid; dashed while lost), its label "#id"
// above the box, its LK region's outline (thin) and its velocity arrow from the box centre
// (`arrow_scale` times one frame's motion). A text line in the top-left corner says
// "frame N  objects K  born B  ended E", plus "  global" on the frames the global treatment
// looked for new objects.
struct ObjectAnnotation {
  long long id = 0;
  cv::Rect2f box;
  cv::Point2f velocity;
  bool lost = false;
  cv::Rect region;  // where LK ran, may be empty
};
struct ObjectsAnnotation {
  long long index = 0;  // 0-based (shown 1-based)
  std::vector<ObjectAnnotation> objects;
  long long born = 0, ended = 0;
  bool global = false;
};
// A bright BGR colour per id, different for neighbouring ids.
cv::Scalar id_color(long long id);
cv::Mat annotate_objects(const cv::Mat& image, const ObjectsAnnotation& frame,
                         const AnnotateStyle& style = {});

}  // namespace roiflow::report
