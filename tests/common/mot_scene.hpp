// A fixed-camera scene for the multi-object tests: textured objects moving at constant velocity
// over a textured, static background, with their exact boxes.
//
//   roiflow::test::MotScene scene({320, 240}, {{{20, 100, 24, 40}, {3, 0}}, {{280, 100, 24, 40},
//                                                                          {-3, 0}}});
//   for (int t = 0; t < 60; ++t) { cv::Mat bgr = scene.frame(t); auto boxes = scene.boxes(t); }
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace roiflow::test {

struct MotObject {
  cv::Rect2f box;        // in frame 0
  cv::Point2f velocity;  // pixels per frame
  int first = 0;         // the frame it appears in
  int last = 1 << 30;    // the last frame it is drawn in
};

class MotScene {
 public:
  MotScene(cv::Size size, std::vector<MotObject> objects, unsigned seed = 7)
      : size_(size), objects_(std::move(objects)) {
    cv::RNG rng(seed);
    background_.create(size, CV_8UC3);
    rng.fill(background_, cv::RNG::UNIFORM, 60, 140);
    cv::GaussianBlur(background_, background_, {0, 0}, 2.0);
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      cv::Mat tex(96, 96, CV_8UC3);
      rng.fill(tex, cv::RNG::UNIFORM, 0, 255);
      cv::GaussianBlur(tex, tex, {0, 0}, 1.5);
      cv::normalize(tex, tex, 0, 255, cv::NORM_MINMAX);
      // Each object darker or brighter than the background, and of its own hue.
      const double base = i % 2 == 0 ? 0 : 165;
      const cv::Scalar tint(base + 6.0 * ((i * 3) % 5), base + 6.0 * ((i * 7) % 5),
                            base + 6.0 * ((i * 11) % 5));
      tex = tex * 0.25 + tint;
      textures_.push_back(tex);
    }
  }

  cv::Size size() const { return size_; }
  int count() const { return static_cast<int>(objects_.size()); }

  // Object i's box in frame t; empty when it is not in the scene then.
  cv::Rect2f box(std::size_t i, int t) const {
    const MotObject& o = objects_[i];
    if (t < o.first || t > o.last) return {};
    return o.box + o.velocity * static_cast<float>(t);
  }

  cv::Mat frame(int t) const {
    cv::Mat out = background_.clone();
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      const cv::Rect2f b = box(i, t);
      if (b.area() <= 0) continue;
      const cv::Rect r(cvRound(b.x), cvRound(b.y), cvRound(b.width), cvRound(b.height));
      const cv::Rect inside = r & cv::Rect(0, 0, size_.width, size_.height);
      if (inside.empty()) continue;
      cv::Mat tex;
      cv::resize(textures_[i], tex, r.size());
      tex(inside - r.tl()).copyTo(out(inside));
    }
    return out;
  }

  cv::Mat gray(int t) const {
    cv::Mat g;
    cv::cvtColor(frame(t), g, cv::COLOR_BGR2GRAY);
    return g;
  }

 private:
  cv::Size size_;
  std::vector<MotObject> objects_;
  cv::Mat background_;
  std::vector<cv::Mat> textures_;
};

inline double box_iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const double inter = (a & b).area();
  const double uni = static_cast<double>(a.area()) + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

}  // namespace roiflow::test
