#include "tracking/start_motion_impl.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "tracking/motion_detector.hpp"

namespace roiflow::tracking::detail {

cv::Mat relative_motion(const cv::Mat& back_flow, const cv::Mat& confidence, cv::Size size,
                        double texture, cv::Mat& textured) {
  cv::Mat motion;
  if (back_flow.size() == size)
    motion = back_flow.clone();
  else
    cv::resize(back_flow, motion, size, 0, 0, cv::INTER_AREA);
  motion *= -1.0;
  std::vector<float> us, vs;
  const int step = std::max(1, std::min(size.width, size.height) / 64);
  for (int y = step / 2; y < motion.rows; y += step) {
    const cv::Vec2f* row = motion.ptr<cv::Vec2f>(y);
    for (int x = step / 2; x < motion.cols; x += step) {
      us.push_back(row[x][0]);
      vs.push_back(row[x][1]);
    }
  }
  if (us.empty()) return motion;
  const auto mid = [](std::vector<float>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const cv::Scalar background(mid(us), mid(vs));
  cv::subtract(motion, background, motion);
  textured = cv::Mat(size, CV_8U, cv::Scalar(255));
  if (texture <= 0) return motion;
  cv::Mat conf;
  if (confidence.size() == size)
    conf = confidence;
  else
    cv::resize(confidence, conf, size, 0, 0, cv::INTER_AREA);
  std::vector<float> textures;
  for (int y = step / 2; y < conf.rows; y += step) {
    const float* row = conf.ptr<float>(y);
    for (int x = step / 2; x < conf.cols; x += step)
      textures.push_back(row[x]);
  }
  const double limit = texture * mid(textures);
  cv::compare(conf, limit, textured, cv::CMP_GE);
  return motion;
}

cv::Mat flow_motion_state(const cv::Mat& motion, double moving) {
  cv::Mat state(motion.size(), CV_8U);
  const float m2 = static_cast<float>(moving * moving), s2 = m2 / 4;
  for (int y = 0; y < motion.rows; ++y) {
    const cv::Vec2f* v = motion.ptr<cv::Vec2f>(y);
    std::uint8_t* out = state.ptr<std::uint8_t>(y);
    for (int x = 0; x < motion.cols; ++x) {
      const float d2 = v[x][0] * v[x][0] + v[x][1] * v[x][1];
      out[x] = d2 >= m2 ? 2 : d2 < s2 ? 1 : 0;
    }
  }
  return state;
}

std::vector<cv::Rect> motion_modes(const cv::Mat& labels, const cv::Mat& mask,
                                   const cv::Mat& motion, int label, const cv::Rect& whole,
                                   double moving, int min_pixels) {
  std::vector<cv::Point> points;
  std::vector<cv::Vec2f> velocity;
  const float m2 = static_cast<float>(moving * moving);
  for (int y = whole.y; y < whole.br().y; ++y) {
    const int* l = labels.ptr<int>(y);
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const cv::Vec2f* v = motion.ptr<cv::Vec2f>(y);
    for (int x = whole.x; x < whole.br().x; ++x) {
      if (l[x] != label || m[x] == 0 || !(v[x][0] * v[x][0] + v[x][1] * v[x][1] >= m2)) continue;
      points.emplace_back(x, y);
      velocity.push_back(v[x]);
    }
  }
  constexpr int kHalfBins = 24, kBins = 2 * kHalfBins + 1;
  std::vector<int> mode_of(points.size(), -1);
  std::vector<cv::Rect> boxes;
  for (int mode = 0; mode < 8; ++mode) {
    std::vector<int> histogram(kBins * kBins, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (mode_of[i] >= 0) continue;
      const int bx = static_cast<int>(std::lround(velocity[i][0])) + kHalfBins;
      const int by = static_cast<int>(std::lround(velocity[i][1])) + kHalfBins;
      if (bx >= 0 && by >= 0 && bx < kBins && by < kBins) ++histogram[by * kBins + bx];
    }
    int best = 0, best_x = 0, best_y = 0;
    for (int by = 1; by + 1 < kBins; ++by) {
      for (int bx = 1; bx + 1 < kBins; ++bx) {
        int sum = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            sum += histogram[(by + dy) * kBins + bx + dx];
        if (sum > best) {
          best = sum;
          best_x = bx;
          best_y = by;
        }
      }
    }
    if (best < min_pixels) break;
    // The mean velocity of the densest bin's neighbourhood, then its pixels.
    cv::Vec2f centre(0, 0);
    int count = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (mode_of[i] >= 0) continue;
      if (std::abs(velocity[i][0] - static_cast<float>(best_x - kHalfBins)) <= 1.5f &&
          std::abs(velocity[i][1] - static_cast<float>(best_y - kHalfBins)) <= 1.5f) {
        centre += velocity[i];
        ++count;
      }
    }
    if (count == 0) break;
    centre *= 1.0f / static_cast<float>(count);
    const float radius = std::max(1.0f, 0.25f * static_cast<float>(cv::norm(centre)));
    int taken = 0;
    cv::Rect box;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (mode_of[i] >= 0 || cv::norm(velocity[i] - centre) > radius) continue;
      mode_of[i] = mode;
      const cv::Rect px(points[i].x, points[i].y, 1, 1);
      box = taken++ == 0 ? px : box | px;
    }
    if (taken < min_pixels) break;
    boxes.push_back(box);
  }
  return boxes;
}

bool split_by_motion(const cv::Mat& labels, const cv::Mat& mask, const cv::Mat& motion, int label,
                     const cv::Rect& whole, double moving, int min_pixels, double overlap,
                     std::vector<cv::Rect>& out) {
  const std::vector<cv::Rect> boxes =
      motion_modes(labels, mask, motion, label, whole, moving, min_pixels);
  // A part moving otherwise inside another's box (a walker's legs) is not an object of its own.
  std::vector<cv::Rect2f> merged(boxes.begin(), boxes.end());
  merged = merge_nested(std::move(merged), overlap);
  if (merged.size() < 2) return false;
  for (const cv::Rect2f& b : merged)
    out.emplace_back(b);
  return true;
}

}  // namespace roiflow::tracking::detail
