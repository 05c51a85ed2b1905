#include "eval/traffic_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/scene_parts.hpp"

namespace roiflow::eval {
namespace {

constexpr double kMinVisibleSide = 8.0;  // ground truth lists a vehicle from this size up
constexpr double kSpeedSwing = 0.6;      // lane speed within (1 -/+ this) x its mean
constexpr int kNoiseFields = 16;
constexpr double kNoiseBankBytes = 96.0 * 1024 * 1024;
// h0, v0, h1, v1, h2, h3: a few vehicles already drive on crossing lanes.
constexpr int kLaneOrder[kTrafficLanes] = {0, 4, 1, 5, 2, 3};

// Body colours (BGR) far from the background's muted mid-grey, in gray as well as in colour.
const cv::Scalar kBodies[] = {{30, 30, 150},  {110, 40, 20},  {25, 25, 25},    {225, 225, 230},
                              {40, 200, 230}, {30, 120, 230}, {195, 195, 190}, {40, 110, 30},
                              {200, 90, 30},  {40, 20, 90},   {160, 60, 160},  {20, 60, 20}};

int scaled_pixels(double pixels, double scale) {
  return std::max(static_cast<int>(kMinVisibleSide), static_cast<int>(std::lround(pixels * scale)));
}

// A vehicle pointing right, `size` = length x width: textured body, light stripe, two dark
// windows, dark wheels at the sides.
cv::Mat draw_traffic_vehicle(cv::Size size, cv::RNG& rng) {
  const cv::Scalar body = kBodies[rng.uniform(0, static_cast<int>(std::size(kBodies)))];
  cv::Mat v(size, CV_32FC3, body);
  detail::add_octaves(v, rng, {8, 4, 2}, 7.0);
  const int w = size.width, h = size.height;
  cv::rectangle(v, cv::Rect(w / 12, h * 2 / 5, w * 5 / 6, std::max(1, h / 6)),
                cv::Scalar(205, 210, 220), cv::FILLED, cv::LINE_AA);
  const cv::Scalar glass(70, 55, 40);
  cv::rectangle(v, cv::Rect(w * 3 / 5, h / 6, w / 5, h * 2 / 3), glass, cv::FILLED, cv::LINE_AA);
  cv::rectangle(v, cv::Rect(w / 6, h / 5, w / 6, h * 3 / 5), glass, cv::FILLED, cv::LINE_AA);
  const cv::Scalar tyre(20, 20, 20);
  const int r = std::max(1, h / 7);
  for (const int x : {w / 5, w * 4 / 5})
    for (const int y : {r, h - 1 - r})
      cv::circle(v, cv::Point(x, y), r, tyre, cv::FILLED, cv::LINE_AA);
  detail::add_octaves(v, rng, {3}, 3.0);
  return v;
}

}  // namespace

void TrafficSceneParams::validate() const {
  if (size.width < 64 || size.height < 64 || size.width > 8192 || size.height > 8192) {
    throw Error("traffic scene: size must be between 64x64 and 8192x8192, got " +
                number_text(size.width) + "x" + number_text(size.height));
  }
  if (frames < 1) throw Error("traffic scene: frames must be >= 1, got " + number_text(frames));
  if (objects < 1 || objects > kMaxTrafficObjects) {
    throw Error("traffic scene: objects must be in 1.." + std::to_string(kMaxTrafficObjects) +
                ", got " + std::to_string(objects));
  }
  if (!(noise >= 0 && noise <= 50)) {
    throw Error("traffic scene: noise must be in [0, 50], got " + number_text(noise));
  }
}

TrafficScene::TrafficScene(const TrafficSceneParams& params) : params_(params) {
  params_.validate();
  const double width = params_.size.width, height = params_.size.height;
  const double scale = std::min(width / 640.0, height / 480.0);
  cv::RNG rng(detail::mix(params_.seed, 100));

  // Vehicles: lane, size and texture.
  vehicles_.resize(params_.objects);
  std::vector<int> per_lane(kTrafficLanes, 0);
  std::vector<double> longest(kTrafficLanes, 0.0);
  lanes_.resize(kTrafficLanes);
  for (int l = 0; l < kTrafficLanes; ++l) {
    Lane& lane = lanes_[l];
    lane.horizontal = l < 4;
    lane.direction = (l % 2 == 0) ? 1 : -1;
    lane.centre = lane.horizontal ? height * (0.2 + 0.2 * l) : width * (0.3 + 0.4 * (l - 4));
    lane.extent = lane.horizontal ? width : height;
    lane.speed = rng.uniform(2.0, 3.5) * scale;
    lane.period = rng.uniform(80.0, 160.0);
    lane.phase = rng.uniform(0.0, 2 * std::numbers::pi);
  }
  std::vector<cv::Size> sizes(params_.objects);
  for (int v = 0; v < params_.objects; ++v) {
    Vehicle& vehicle = vehicles_[v];
    vehicle.lane = kLaneOrder[v % kTrafficLanes];
    ++per_lane[vehicle.lane];
    const int length = scaled_pixels(rng.uniform(52.0, 84.0), scale);
    const int across = scaled_pixels(rng.uniform(28.0, 38.0), scale);
    sizes[v] = {length, across};
    longest[vehicle.lane] = std::max(longest[vehicle.lane], static_cast<double>(length));
    vehicle.lateral = rng.uniform(-4.0, 4.0) * scale;
  }
  // Cycles: a lane's vehicles evenly spread, each leaving the frame before it comes back.
  const double gap = 24 * scale;
  for (int l = 0; l < kTrafficLanes; ++l) {
    Lane& lane = lanes_[l];
    const int m = std::max(1, per_lane[l]);
    lane.cycle = std::max(lane.extent + longest[l] + gap, m * (longest[l] + gap));
    const double spacing = lane.cycle / m;
    lane.start = (m - 1) * spacing + rng.uniform(0.0, 1.0) * spacing;
  }
  std::vector<int> rank(kTrafficLanes, 0);
  for (int v = 0; v < params_.objects; ++v) {
    Vehicle& vehicle = vehicles_[v];
    const Lane& lane = lanes_[vehicle.lane];
    vehicle.offset = rank[vehicle.lane]++ * lane.cycle / std::max(1, per_lane[vehicle.lane]);
    cv::RNG texture_rng(detail::mix(params_.seed, 1000 + static_cast<std::uint64_t>(v)));
    cv::Mat texture = draw_traffic_vehicle(sizes[v], texture_rng);
    if (lane.direction < 0) cv::flip(texture, texture, 1);
    if (!lane.horizontal) cv::transpose(texture, texture);
    vehicle.alpha =
        detail::rounded_rect_alpha(texture.size(), 0.22 * std::min(texture.cols, texture.rows));
    cv::Mat alpha3;
    cv::merge(std::vector<cv::Mat>(3, vehicle.alpha), alpha3);
    vehicle.texture = texture.mul(alpha3);
  }

  cv::RNG background_rng(detail::mix(params_.seed, 0));
  background_ = detail::draw_background(params_.size, background_rng);

  // Camera noise: drawing a frame's worth of normal samples costs more than drawing all the
  // vehicles, so up to kNoiseFields fields are drawn once and cycled (consecutive frames never
  // share one) when they fit in kNoiseBankBytes; larger frames draw theirs per frame.
  const double field_bytes = 6.0 * params_.size.area();
  const int fields =
      static_cast<int>(std::min<double>(kNoiseFields, kNoiseBankBytes / field_bytes));
  if (params_.noise > 0 && fields >= 4) {
    for (int k = 0; k < fields; ++k)
      noise_bank_.push_back(noise_field(static_cast<std::uint64_t>(k)));
  }
}

cv::Mat TrafficScene::noise_field(std::uint64_t stream) const {
  cv::RNG rng(detail::mix(params_.seed, 2 + stream));
  cv::Mat noise(params_.size, CV_16SC3);
  // Whole gray levels: adding them to the 8-bit frame rounds as adding float noise would,
  // within one level.
  rng.fill(noise, cv::RNG::NORMAL, 0.0, params_.noise);
  return noise;
}

void TrafficScene::check_index(long long i) const {
  if (i < 0 || i >= params_.frames) {
    throw Error("traffic scene: frame " + std::to_string(i) + " is outside 0.." +
                std::to_string(params_.frames - 1));
  }
}

double TrafficScene::driven(const Lane& lane, long long i) const {
  const double t = static_cast<double>(i);
  const double w = 2 * std::numbers::pi / lane.period;
  // The integral of speed * (1 + swing * sin(w t + phase)) from 0 to t.
  return lane.speed * (t + kSpeedSwing / w * (std::cos(lane.phase) - std::cos(w * t + lane.phase)));
}

std::vector<TrafficScene::Placed> TrafficScene::place(long long i) const {
  std::vector<Placed> placed;
  std::vector<double> lane_driven(kTrafficLanes);
  for (int l = 0; l < kTrafficLanes; ++l)
    lane_driven[l] = driven(lanes_[l], i);
  for (int v = 0; v < params_.objects; ++v) {
    const Vehicle& vehicle = vehicles_[v];
    const Lane& lane = lanes_[vehicle.lane];
    const double along = lane.horizontal ? vehicle.texture.cols : vehicle.texture.rows;
    const double across = lane.horizontal ? vehicle.texture.rows : vehicle.texture.cols;
    // u: pixels driven in the vehicle's own cycles. The part of a cycle before
    // C - extent - length is spent waiting outside the frame; then the vehicle crosses.
    const double u = lane.start - vehicle.offset + lane_driven[vehicle.lane];
    const double pass = std::floor(u / lane.cycle);
    const double q = u - pass * lane.cycle;
    const double lead = q - (lane.cycle - lane.extent - along);  // front edge past the border
    if (lead <= 0 || lead >= lane.extent + along) continue;
    const double near = lane.direction > 0 ? lead - along : lane.extent - lead;
    const double side = lane.centre + vehicle.lateral - 0.5 * across;
    Placed p;
    p.vehicle = v;
    p.id = v + 1 + static_cast<int>(pass) * params_.objects;
    p.box = lane.horizontal ? cv::Rect2d(near, side, along, across)
                            : cv::Rect2d(side, near, across, along);
    placed.push_back(p);
  }
  return placed;
}

std::vector<MotBox> TrafficScene::boxes(long long i) const {
  check_index(i);
  const cv::Rect2d frame(0, 0, params_.size.width, params_.size.height);
  std::vector<MotBox> out;
  for (const Placed& p : place(i)) {
    const cv::Rect2d clipped = p.box & frame;
    if (clipped.width < kMinVisibleSide || clipped.height < kMinVisibleSide) continue;
    MotBox b;
    b.frame = static_cast<int>(i + 1);
    b.id = p.id;
    // MOTChallenge's 1-based pixel coordinates: drawn pixel column 0 is x = 1.
    b.box = cv::Rect2d(clipped.x + 1, clipped.y + 1, clipped.width, clipped.height);
    out.push_back(b);
  }
  std::sort(out.begin(), out.end(), [](const MotBox& a, const MotBox& b) { return a.id < b.id; });
  return out;
}

std::vector<MotBox> TrafficScene::ground_truth() const {
  std::vector<MotBox> all;
  for (long long i = 0; i < params_.frames; ++i) {
    const std::vector<MotBox> frame = boxes(i);
    all.insert(all.end(), frame.begin(), frame.end());
  }
  return all;
}

cv::Mat TrafficScene::render(long long i) const {
  check_index(i);
  cv::Mat frame = background_.clone();
  const cv::Rect bounds(cv::Point(), params_.size);
  for (const Placed& p : place(i)) {  // in vehicle order: larger indices on top
    const Vehicle& vehicle = vehicles_[p.vehicle];
    const cv::Rect region = cv::Rect(static_cast<int>(std::floor(p.box.x)) - 1,
                                     static_cast<int>(std::floor(p.box.y)) - 1,
                                     vehicle.texture.cols + 3, vehicle.texture.rows + 3) &
                            bounds;
    if (region.empty()) continue;
    // Texture pixel u covers [u, u + 1) and lands on [box.x + u, box.x + u + 1).
    const cv::Matx23d warp(1, 0, p.box.x - region.x, 0, 1, p.box.y - region.y);
    cv::Mat colour, alpha;
    cv::warpAffine(vehicle.texture, colour, warp, region.size(), cv::INTER_LINEAR,
                   cv::BORDER_CONSTANT);
    cv::warpAffine(vehicle.alpha, alpha, warp, region.size(), cv::INTER_LINEAR,
                   cv::BORDER_CONSTANT);
    cv::Mat roi;
    frame(region).convertTo(roi, CV_32FC3);
    cv::Mat keep3;
    cv::merge(std::vector<cv::Mat>(3, 1.0 - alpha), keep3);
    const cv::Mat blended = roi.mul(keep3) + colour;
    blended.convertTo(frame(region), CV_8UC3);
  }
  if (params_.noise > 0) {
    if (!noise_bank_.empty()) {
      cv::add(frame,
              noise_bank_[static_cast<std::size_t>(i % static_cast<long long>(noise_bank_.size()))],
              frame, cv::noArray(), CV_8U);
    } else {
      cv::add(frame, noise_field(static_cast<std::uint64_t>(i)), frame, cv::noArray(), CV_8U);
    }
  }
  return frame;
}

}  // namespace roiflow::eval
