// The paper's global treatment: find the moving object in the whole frame, by a background
// model (fixed camera, nothing known: MOG2 on a reduced copy, morphology, contours; the target's
// colour/shape/size signature picks it among the moving objects) or by its appearance (a known
// target, or a moving camera: multi-scale normalised cross-correlation of its template).
// docs/STAGES.md has the details.
//
//   roiflow::tracking::GlobalDetector detector;
//   detector.observe(bgr);  // every frame (or every k-th, with weight k): the background model
//   const std::vector<roiflow::tracking::Detection> objects = detector.moving_objects();
//   if (objects.empty()) return;  // warm-up, or nothing moves
//   detector.set_target(bgr, objects[0].box);  // biggest first
//   const auto found = detector.find_target(bgr, frame_t, {320, 240}, /*by_appearance=*/true);
//   if (found) std::cout << found->box << "\n";
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace roiflow::tracking {

struct GlobalDetectorParams {
  int history = 100;       // frames the background model remembers (MOG2 history), >= 2
  int warmup = 3;          // moving_objects() stays empty for this many observed frames
  int work_width = 320;    // the background model works on frames shrunk by the whole factor
                           // that brings them nearest this width (768 -> 384, 640 -> 320,
                           // 1920 -> 320; never enlarged); 0 = full resolution
  double min_area = 64;    // smallest object, in full-resolution pixels
  double min_score = 0.5;  // a re-detection below this similarity is no detection, (0, 1)
  std::vector<double> appearance_scales{0.8, 0.9, 1.0, 1.1, 1.25};  // relative to the target's
                                                                    // last known size
  void validate() const;  // throws roiflow::Error naming the bad value
};

struct Detection {
  cv::Rect2f box;          // full-resolution pixels
  cv::Point2f barycentre;  // of the object's edge contour (the paper's object position)
  double score = 0;        // moving_objects: area in pixels; find_target: similarity in [0, 1]
};

class GlobalDetector {
 public:
  explicit GlobalDetector(const GlobalDetectorParams& params = {});

  // Updates the background model with a frame (8-bit BGR or gray, one size for a run), in order.
  // The frame stands for `weight` frames of video (> 0): the model learns at
  // min(1, weight / history), so a caller that observes only every k-th frame can keep the
  // model's memory in frames of video by passing k.
  void observe(const cv::Mat& image, double weight = 1.0);
  // Moving objects of the last observed frame, biggest first; empty during warm-up.
  std::vector<Detection> moving_objects() const;

  // Remembers the target: its template (gray), signature and size, from `image` (8-bit BGR or
  // gray) at `box` (clipped to the frame; throws roiflow::Error when nothing is left).
  void set_target(const cv::Mat& image, const cv::Rect2f& box);
  bool has_target() const;
  cv::Size2f target_size() const;  // the size last given to set_target
  // Updates the expected size of the target (the tracker follows its scale) without changing
  // the appearance captured by set_target.
  void set_target_size(cv::Size2f size);
  // How alike the colours of `box` in `image` (the kind of picture set_target() was given) and
  // the target's are: 1 - the Bhattacharyya distance of their colour histograms, the best over
  // the target's first look and the recent ones remember_colour() kept, in [0, 1]; -1 when the
  // box leaves fewer than 2x2 pixels inside the image or no target is set.
  double colour_similarity(const cv::Mat& image, const cv::Rect2f& box) const;
  // Keeps the colours of `box` in `image` as a recent look of the target (the last few are
  // kept besides the first; set_target() forgets them). Call it on confidently tracked frames.
  void remember_colour(const cv::Mat& image, const cv::Rect2f& box);

  // Finds the target in the whole frame: by appearance (multi-scale NCC of the template) when
  // `by_appearance`, else among the moving objects by signature similarity (the nearest to
  // `near` breaks ties). std::nullopt when nothing reaches `min_score`, or without a target.
  std::optional<Detection> find_target(const cv::Mat& image, const cv::Mat& gray, cv::Point2f near,
                                       bool by_appearance) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace roiflow::tracking
