#include "eval/tracking_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "eval/scene_parts.hpp"

namespace roiflow::eval {
namespace {

constexpr int kMargin = 4;  // pixels kept free between the vehicle and the frame's border

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

namespace detail {

// splitmix64, so that seeds 1, 2, 3... and the per-frame noise streams are unrelated.
std::uint64_t mix(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

namespace {

// Smoothed uniform noise in [-1, 1] with features about `cell` pixels wide.
cv::Mat smooth_noise(cv::RNG& rng, cv::Size size, int cell) {
  cv::Mat grid(size.height / cell + 2, size.width / cell + 2, CV_32F);
  rng.fill(grid, cv::RNG::UNIFORM, -1.f, 1.f);
  cv::Mat out;
  cv::resize(grid, out, size, 0, 0, cv::INTER_CUBIC);
  return out;
}

}  // namespace

// Adds gray noise octaves of the given cell sizes, amplitude growing with the cell (a 1/f-like
// spectrum, as in natural images), each with a slight colour tint.
void add_octaves(cv::Mat& image, cv::RNG& rng, std::initializer_list<int> cells, double gain) {
  for (int cell : cells) {
    const cv::Mat n = smooth_noise(rng, image.size(), cell);
    const double amp = gain * std::pow(static_cast<double>(cell), 0.5);
    cv::Mat channels[3];
    for (auto& c : channels)
      c = n * (amp * rng.uniform(0.85, 1.15));
    cv::Mat tinted;
    cv::merge(channels, 3, tinted);
    image += tinted;
  }
}

cv::Mat draw_background(cv::Size size, cv::RNG& rng) {
  cv::Mat bg(size, CV_32FC3, cv::Scalar(105, 120, 115));
  add_octaves(bg, rng, {96, 48, 24}, 4.0);
  // Soft shapes: the edges and corners a real scene has and noise lacks.
  const int shapes = 6 + size.area() / 40000;
  for (int k = 0; k < shapes; ++k) {
    const double grey = rng.uniform(60.0, 190.0);
    const cv::Scalar colour(grey * rng.uniform(0.85, 1.15), grey * rng.uniform(0.85, 1.15),
                            grey * rng.uniform(0.85, 1.15));
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int r = rng.uniform(8, std::max(9, std::min(size.width, size.height) / 8));
    switch (k % 3) {
      case 0:
        cv::circle(bg, c, r, colour, cv::FILLED, cv::LINE_AA);
        break;
      case 1:
        cv::rectangle(bg, cv::Rect(c.x - r, c.y - r / 2, 2 * r, r), colour, cv::FILLED,
                      cv::LINE_AA);
        break;
      default:
        cv::line(bg, c, c + cv::Point(rng.uniform(-3 * r, 3 * r), rng.uniform(-r, r)), colour,
                 std::max(2, r / 4), cv::LINE_AA);
    }
  }
  add_octaves(bg, rng, {12, 6, 3}, 3.5);
  cv::GaussianBlur(bg, bg, cv::Size(), 0.7);
  cv::Mat out;
  bg.convertTo(out, CV_8UC3);
  return out;
}

// Coverage of the rounded rectangle [0, w) x [0, h) with corner radius r, 4x4 samples a pixel.
cv::Mat rounded_rect_alpha(cv::Size size, double r) {
  cv::Mat alpha(size, CV_32F);
  const double w = size.width, h = size.height;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      int inside = 0;
      for (int sy = 0; sy < 4; ++sy) {
        for (int sx = 0; sx < 4; ++sx) {
          const double px = x + (sx + 0.5) / 4, py = y + (sy + 0.5) / 4;
          const double dx = std::max({r - px, px - (w - r), 0.0});
          const double dy = std::max({r - py, py - (h - r), 0.0});
          inside += dx * dx + dy * dy <= r * r;
        }
      }
      alpha.at<float>(y, x) = static_cast<float>(inside) / 16.f;
    }
  }
  return alpha;
}

}  // namespace detail

namespace {

using detail::add_octaves;
using detail::mix;
using detail::rounded_rect_alpha;

// A vehicle seen from above or the side: a saturated body with fine texture, a light stripe,
// dark windows and a dark rim, so it differs from the muted background in colour and texture.
cv::Mat draw_vehicle(cv::Size size, cv::RNG& rng) {
  // Dark red: it stands out from the background in gray as well as in colour.
  const cv::Scalar body(rng.uniform(20.0, 40.0), rng.uniform(20.0, 40.0),
                        rng.uniform(140.0, 170.0));
  cv::Mat v(size, CV_32FC3, body);
  add_octaves(v, rng, {8, 4, 2}, 9.0);
  const int w = size.width, h = size.height;
  cv::rectangle(v, cv::Rect(w / 10, h * 45 / 100, w * 8 / 10, std::max(2, h / 10)),
                cv::Scalar(200, 210, 225), cv::FILLED, cv::LINE_AA);
  const cv::Scalar glass(70, 55, 40);
  cv::rectangle(v, cv::Rect(w / 5, h / 8, w / 4, h / 4), glass, cv::FILLED, cv::LINE_AA);
  cv::rectangle(v, cv::Rect(w * 11 / 20, h / 8, w / 4, h / 4), glass, cv::FILLED, cv::LINE_AA);
  cv::circle(v, cv::Point(w / 4, h * 3 / 4), std::max(2, h / 8), cv::Scalar(25, 25, 25), cv::FILLED,
             cv::LINE_AA);
  cv::circle(v, cv::Point(w * 3 / 4, h * 3 / 4), std::max(2, h / 8), cv::Scalar(25, 25, 25),
             cv::FILLED, cv::LINE_AA);
  add_octaves(v, rng, {3}, 3.0);
  return v;
}

}  // namespace

void TrackingSceneParams::validate() const {
  if (size.width < 64 || size.height < 64 || size.width > 8192 || size.height > 8192) {
    throw Error("tracking scene: size must be between 64x64 and 8192x8192, got " + num(size.width) +
                "x" + num(size.height));
  }
  if (frames < 3) throw Error("tracking scene: frames must be >= 3, got " + num(frames));
  if (!(scale_change > -0.5 && scale_change <= 1.0)) {
    throw Error("tracking scene: scale_change must be in (-0.5, 1], got " + num(scale_change));
  }
  const double grow = std::max(1.0, 1.0 + scale_change);
  if (!(object.width >= 8 && object.height >= 8) ||
      !(object.width * grow <= size.width / 3.0 && object.height * grow <= size.height / 3.0)) {
    throw Error(
        "tracking scene: object must be at least 8x8 and, at its largest, at most a "
        "third of the frame, got " +
        num(object.width) + "x" + num(object.height));
  }
  if (!(speed_variation >= 0 && speed_variation <= 0.95)) {
    throw Error("tracking scene: speed_variation must be in [0, 0.95], got " +
                num(speed_variation));
  }
  if (jump_frame != -1 && (jump_frame < 1 || jump_frame >= frames)) {
    throw Error("tracking scene: jump_frame must be -1 or in 1.." + num(frames - 1) + ", got " +
                num(jump_frame));
  }
  const double path = size.width - 2 * kMargin - object.width * grow;
  if (!(jump >= 0 && jump <= path / 2)) {
    throw Error("tracking scene: jump must be in [0, " + num(path / 2) + "], got " + num(jump));
  }
  if (!(noise >= 0 && noise <= 50)) {
    throw Error("tracking scene: noise must be in [0, 50], got " + num(noise));
  }
}

TrackingScene::TrackingScene(const TrackingSceneParams& params) : params_(params) {
  params_.validate();
  const int n = params_.frames;
  jump_frame_ = params_.jump_frame == -1 ? n / 2 : params_.jump_frame;

  // Speeds: a smooth profile (fast start, braking, again faster, braking), scaled so
  // that the vehicle ends its path exactly at the right margin, plus the one jump.
  const double grow = std::max(1.0, 1.0 + params_.scale_change);
  const double max_w = params_.object.width * grow, max_h = params_.object.height * grow;
  const double path = params_.size.width - 2 * kMargin - max_w;
  std::vector<double> profile(n, 0.0);
  double total = 0;
  for (int i = 1; i < n; ++i) {
    if (i == jump_frame_) continue;
    const double t = static_cast<double>(i) / (n - 1);
    profile[i] = 1.0 + params_.speed_variation * std::cos(3 * std::numbers::pi * t);
    total += profile[i];
  }
  const double per_unit = (path - params_.jump) / total;
  const double mid_y = 0.5 * params_.size.height;
  const double sway =
      std::min(0.06 * params_.size.height, 0.5 * (params_.size.height - 2 * kMargin - max_h));
  double x = kMargin;
  boxes_.reserve(n);
  for (int i = 0; i < n; ++i) {
    x += i == jump_frame_ ? params_.jump : per_unit * profile[i];
    const double t = static_cast<double>(i) / (n - 1);
    const double s = 1.0 + params_.scale_change * t;
    const double w = params_.object.width * s, h = params_.object.height * s;
    const double cy = mid_y + sway * std::sin(2 * std::numbers::pi * t);
    boxes_.emplace_back(static_cast<float>(x), static_cast<float>(cy - 0.5 * h),
                        static_cast<float>(w), static_cast<float>(h));
  }

  cv::RNG bg_rng(mix(params_.seed, 0));
  background_ = detail::draw_background(params_.size, bg_rng);
  cv::RNG vehicle_rng(mix(params_.seed, 1));
  const cv::Size tex(static_cast<int>(std::ceil(max_w)), static_cast<int>(std::ceil(max_h)));
  alpha_ = rounded_rect_alpha(tex, 0.22 * std::min(tex.width, tex.height));
  const cv::Mat vehicle = draw_vehicle(tex, vehicle_rng);
  cv::Mat alpha3;
  cv::merge(std::vector<cv::Mat>(3, alpha_), alpha3);
  texture_ = vehicle.mul(alpha3);
}

void TrackingScene::check_index(int i) const {
  if (i < 0 || i >= params_.frames) {
    throw Error("tracking scene: frame " + num(i) + " is outside 0.." + num(params_.frames - 1));
  }
}

cv::Rect2f TrackingScene::box(int i) const {
  check_index(i);
  return boxes_[i];
}

cv::Mat TrackingScene::render(int i) const {
  check_index(i);
  const cv::Rect2f b = boxes_[i];
  // Texture pixel u covers [u, u + 1); it lands on [b.x + u * sx, b.x + (u + 1) * sx), so its
  // centre u + 0.5 maps to the frame pixel centre X + 0.5.
  const double sx = b.width / texture_.cols, sy = b.height / texture_.rows;
  const cv::Rect region =
      cv::Rect(static_cast<int>(std::floor(b.x)) - 1, static_cast<int>(std::floor(b.y)) - 1,
               static_cast<int>(std::ceil(b.width)) + 3,
               static_cast<int>(std::ceil(b.height)) + 3) &
      cv::Rect(cv::Point(), params_.size);
  const cv::Matx23d warp(sx, 0, b.x + 0.5 * sx - 0.5 - region.x, 0, sy,
                         b.y + 0.5 * sy - 0.5 - region.y);
  cv::Mat colour, alpha;
  cv::warpAffine(texture_, colour, warp, region.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpAffine(alpha_, alpha, warp, region.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);

  cv::Mat frame;
  background_.convertTo(frame, CV_32FC3);
  cv::Mat roi = frame(region);
  const cv::Mat keep = 1.0 - alpha;
  cv::Mat keep3;
  cv::merge(std::vector<cv::Mat>(3, keep), keep3);
  const cv::Mat blended = roi.mul(keep3) + colour;
  blended.copyTo(roi);
  if (params_.noise > 0) {
    cv::RNG rng(mix(params_.seed, 2 + static_cast<std::uint64_t>(i)));
    cv::Mat noise(params_.size, CV_32FC3);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, params_.noise);
    frame += noise;
  }
  cv::Mat out;
  frame.convertTo(out, CV_8UC3);
  return out;
}

}  // namespace roiflow::eval
