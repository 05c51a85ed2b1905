// A synthetic fixed-camera video with an exact ground-truth box per frame: a textured vehicle
// crosses a textured background, speeding up and braking, growing or shrinking, and once, at
// jump_frame(), jumps further than a 50x50 local region can follow, so a tracker must fall back
// to a global search. Frames are rendered on demand and deterministically (noise included).
//
//   const roiflow::eval::TrackingScene scene;  // 640x480, 150 frames
//   for (int i = 0; i < scene.frames(); ++i) {
//     const cv::Mat frame = scene.render(i);   // CV_8UC3 (BGR)
//     const cv::Rect2f truth = scene.box(i);   // where the vehicle is
//     if (i == scene.jump_frame()) std::cout << truth << "\n";
//   }
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::eval {

struct TrackingSceneParams {
  cv::Size size{640, 480};        // frame size, each side 64..8192
  int frames = 150;               // number of frames, >= 3
  std::uint64_t seed = 1;         // textures, shapes and camera noise
  cv::Size2f object{72.f, 44.f};  // the vehicle's size in frame 0, each side >= 8 pixels and
                                  // with its path at most a third of the frame
  double speed_variation = 0.6;   // speed swings between (1 -/+ this) x its mean, [0, 0.95]
  int jump_frame = -1;            // frame whose motion from the previous one is the jump,
                                  // 1..frames-1; -1 = the middle of the run
  double jump = 48.0;             // pixels of that jump (to the right), >= 0, at most half
                                  // the path
  double scale_change = 0.15;     // relative size change from the first to the last frame,
                                  // (-0.5, 1]
  double noise = 2.0;             // camera noise, standard deviation in gray levels, 0..50
  void validate() const;          // throws roiflow::Error naming the bad value
};

class TrackingScene {
 public:
  // Throws roiflow::Error on bad params. Draws the textures once (a few ms at 640x480).
  explicit TrackingScene(const TrackingSceneParams& params = {});

  int frames() const { return params_.frames; }
  cv::Size size() const { return params_.size; }
  int jump_frame() const { return jump_frame_; }
  const TrackingSceneParams& params() const { return params_; }

  // Frame i (0 <= i < frames()) as CV_8UC3 BGR; throws roiflow::Error for another i.
  cv::Mat render(int i) const;
  // The vehicle's exact box in frame i; throws roiflow::Error for an i out of range.
  cv::Rect2f box(int i) const;
  // The static background alone, without the vehicle and without noise (CV_8UC3).
  const cv::Mat& background() const { return background_; }

 private:
  void check_index(int i) const;

  TrackingSceneParams params_;
  int jump_frame_ = 0;
  cv::Mat background_;  // CV_8UC3
  cv::Mat texture_;     // CV_32FC3, the vehicle at its largest size, premultiplied by alpha_
  cv::Mat alpha_;       // CV_32FC1, its anti-aliased rounded-rectangle mask
  std::vector<cv::Rect2f> boxes_;
};

}  // namespace roiflow::eval
