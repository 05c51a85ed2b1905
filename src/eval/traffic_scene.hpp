// TrafficScene: a synthetic fixed-camera crossroads with many vehicles and an exact
// ground-truth box for each, in MOTChallenge form.
//
//   roiflow::eval::TrafficScene scene({.size = {640, 480}, .frames = 300, .objects = 16});
//   for (int i = 0; i < scene.frames(); ++i) {
//     cv::Mat frame = scene.render(i);                        // CV_8UC3 (BGR)
//     std::vector<roiflow::eval::MotBox> truth = scene.boxes(i);  // frame i + 1, ids from 1
//   }
//   roiflow::eval::write_mot("gt_mot.txt", scene.ground_truth());
//
// `objects` textured vehicles (rounded rectangles in saturated or very dark or light colours,
// each with its own fine texture, windows and a light stripe) drive on six straight lanes over
// a static textured background (eval::TrackingScene's): four horizontal lanes, alternately to
// the right and to the left, and two vertical lanes, down and up, that cross all four, so
// vehicles on crossing lanes overlap and pass over one another (a vehicle with a larger index
// is drawn above). Vehicle v drives on lane (h0, v0, h1, v1, h2, h3)[v mod 6]. Every lane has
// its own speed that swings smoothly between 0.4 and 1.6 times its mean (about 2 to 3.5 px a
// frame at 640x480), so the vehicles of a lane keep their spacing and never overtake. A lane's
// vehicles are spread evenly over a cycle longer than the lane: each enters at one border,
// crosses the frame, leaves at the other, and comes back later as a new object (a new id). At
// frame 0 the vehicles are spread along their lanes, most of them inside the frame.
// Sizes and speeds scale with min(width / 640, height / 480) (vehicles at least 8 px a side).
//
// Ground truth: a vehicle's box is the exact extent of its drawn shape (sub-pixel position,
// integer size), clipped to the frame, in MOTChallenge's 1-based pixel coordinates (a shape
// drawn from pixel column 0 has x = 1, as MOTChallenge ground truth and roiflow's --mot
// output count); it is listed, with conf 1, in every frame where that
// clipped box is at least 8 px on each side, whether or not another vehicle hides part of it
// (MOTChallenge also keeps occluded objects). Ids: vehicle v on its first pass is v + 1; its
// pass number p (from 0) makes it v + 1 + p * objects. Frames are rendered on demand,
// deterministically (camera noise included), and any frame count works: traffic keeps
// flowing, which makes long soak inputs. Camera noise (Gaussian, whole gray levels) cycles
// through 16 fields drawn once where they fit in 96 MB (up to about 1080p), else is drawn per
// frame.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "eval/mot.hpp"

namespace roiflow::eval {

struct TrafficSceneParams {
  cv::Size size{640, 480};  // each side 64..8192
  long long frames = 300;   // >= 1
  int objects = 16;         // vehicles in circulation, 1..kMaxTrafficObjects
  std::uint64_t seed = 1;   // textures, colours, lane speeds and camera noise
  double noise = 2.0;       // camera noise, standard deviation in gray levels, 0..50
  void validate() const;    // throws roiflow::Error naming the bad value
};

inline constexpr int kMaxTrafficObjects = 256;
inline constexpr int kTrafficLanes = 6;

class TrafficScene {
 public:
  // Throws roiflow::Error on bad params. Draws the background and the vehicles once.
  explicit TrafficScene(const TrafficSceneParams& params = {});

  long long frames() const { return params_.frames; }
  cv::Size size() const { return params_.size; }
  int objects() const { return params_.objects; }
  const TrafficSceneParams& params() const { return params_; }

  // Frame i (0 <= i < frames()) as CV_8UC3 BGR; throws roiflow::Error for another i.
  cv::Mat render(long long i) const;
  // The ground-truth boxes of frame i (MotBox::frame = i + 1), sorted by id.
  std::vector<MotBox> boxes(long long i) const;  // 1-based x, y
  // boxes(i) of every frame, in frame order.
  std::vector<MotBox> ground_truth() const;
  // The static background alone (CV_8UC3), without vehicles and noise.
  const cv::Mat& background() const { return background_; }

 private:
  struct Lane {
    bool horizontal = true;
    int direction = 1;  // +1: right or down, -1: left or up
    double centre = 0;  // y of a horizontal lane, x of a vertical one
    double extent = 0;  // frame width or height along the lane
    double speed = 0;   // mean pixels per frame
    double period = 0;  // frames of one speed swing
    double phase = 0;   // radians
    double cycle = 0;   // pixels after which a vehicle comes back
    double start = 0;   // pixels driven by the lane's first vehicle at frame 0
  };
  struct Vehicle {
    int lane = 0;
    double offset = 0;   // behind the lane's first vehicle, pixels
    double lateral = 0;  // from the lane's centre line, pixels
    cv::Mat texture;     // CV_32FC3, premultiplied by alpha
    cv::Mat alpha;       // CV_32FC1
  };
  struct Placed {
    int vehicle = 0;
    int id = 0;
    cv::Rect2d box;  // unclipped
  };

  void check_index(long long i) const;
  double driven(const Lane& lane, long long i) const;
  std::vector<Placed> place(long long i) const;
  cv::Mat noise_field(std::uint64_t stream) const;  // CV_16SC3 camera noise

  TrafficSceneParams params_;
  std::vector<Lane> lanes_;
  std::vector<Vehicle> vehicles_;
  cv::Mat background_;
  std::vector<cv::Mat> noise_bank_;  // cycled camera noise fields (empty: drawn per frame)
};

}  // namespace roiflow::eval
