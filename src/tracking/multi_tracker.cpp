#include "tracking/multi_tracker.hpp"

#include "tracking/motion_split.hpp"

// 8x8 matrices gain nothing from Eigen's vector code, and GCC 12 warns (falsely) inside its
// AVX-512 paths under -march=native.
#define EIGEN_DONT_VECTORIZE
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "core/assignment.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/select_impl.hpp"

namespace roiflow::tracking {
namespace {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat8 = Eigen::Matrix<double, 8, 8, Eigen::RowMajor>;

Mat8 transition() {
  Mat8 f = Mat8::Identity();
  for (int i = 0; i < 4; ++i)
    f(i, i + 4) = 1.0;
  return f;
}

// Noise scaled with the object's height (as SORT/DeepSORT do): a person 100 px tall jitters
// more in pixels than one 30 px tall.
constexpr double kStdPosition = 1.0 / 20;
constexpr double kStdVelocity = 1.0 / 160;
constexpr double kStdLk = 1.0 / 40;

double iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const double inter = (a & b).area();
  const double uni = static_cast<double>(a.area()) + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

cv::Rect2f frame_rect(cv::Size size) {
  return {0.f, 0.f, static_cast<float>(size.width), static_cast<float>(size.height)};
}

double visible_share(const cv::Rect2f& box, cv::Size size) {
  return box.area() > 0 ? (box & frame_rect(size)).area() / box.area() : 0.0;
}

cv::Vec2f sample(const cv::Mat& flow, cv::Point2f p) {
  const int x0 = static_cast<int>(std::floor(p.x)), y0 = static_cast<int>(std::floor(p.y));
  const float ax = p.x - static_cast<float>(x0), ay = p.y - static_cast<float>(y0);
  const int x1 = std::min(x0 + 1, flow.cols - 1), y1 = std::min(y0 + 1, flow.rows - 1);
  const auto& f = flow;
  return (1 - ay) * ((1 - ax) * f.at<cv::Vec2f>(y0, x0) + ax * f.at<cv::Vec2f>(y0, x1)) +
         ay * ((1 - ax) * f.at<cv::Vec2f>(y1, x0) + ax * f.at<cv::Vec2f>(y1, x1));
}

// The median of a copy of `v` (the caller's values stay as they are).
float median(std::vector<float> v) {
  return detail::median(v);
}

}  // namespace

void MultiTrackerParams::validate() const {
  auto fail = [](const std::string& what) { throw Error("multi-object tracker: " + what); };
  detector.validate();
  lk.validate();
  if (lk_context < -1 || lk_context > 1000)
    fail("lk_context must be in -1..1000, got " + number_text(lk_context));
  if (!(split_grow == 0 || (split_grow >= 1 && split_grow <= 1000)))
    fail("split_grow must be 0 or in [1, 1000], got " + number_text(split_grow));
  if (!(split_keep > 0 && split_keep <= 1))
    fail("split_keep must be in (0, 1], got " + number_text(split_keep));
  if (margin < 0 || margin > 1000) fail("margin must be in 0..1000, got " + number_text(margin));
  if (tile_rows < 8 || tile_rows > 4096)
    fail("tile_rows must be in 8..4096, got " + number_text(tile_rows));
  if (max_points < 16 || max_points > 1000000)
    fail("max_points must be in 16..1e6, got " + number_text(max_points));
  if (!(fb_threshold > 0) || !std::isfinite(fb_threshold))
    fail("fb_threshold must be > 0, got " + number_text(fb_threshold));
  if (!(min_inliers >= 0 && min_inliers < 1))
    fail("min_inliers must be in [0, 1), got " + number_text(min_inliers));
  if (!(min_moving >= 0 && min_moving < 1))
    fail("min_moving must be in [0, 1), got " + number_text(min_moving));
  if (!(min_changed >= 0 && min_changed < 1))
    fail("min_changed must be in [0, 1), got " + number_text(min_changed));
  if (!(merge_own > 0 && merge_own <= 1))
    fail("merge_own must be in (0, 1], got " + number_text(merge_own));
  if (!(lk_size_decay >= 0 && lk_size_decay <= 1))
    fail("lk_size_decay must be in [0, 1], got " + number_text(lk_size_decay));
  if (!(gate_iou >= 0 && gate_iou < 1))
    fail("gate_iou must be in [0, 1), got " + number_text(gate_iou));
  if (min_hits < 1) fail("min_hits must be >= 1, got " + number_text(min_hits));
  if (max_lost < 0) fail("max_lost must be >= 0, got " + number_text(max_lost));
  if (still_frames < 1) fail("still_frames must be >= 1, got " + number_text(still_frames));
  if (parked_frames < 1) fail("parked_frames must be >= 1, got " + number_text(parked_frames));
  if (parked_age < 0) fail("parked_age must be >= 0, got " + number_text(parked_age));
  if (!(parked_motion >= 0) || !std::isfinite(parked_motion))
    fail("parked_motion must be >= 0, got " + number_text(parked_motion));
  if (!(min_visible > 0 && min_visible <= 1))
    fail("min_visible must be in (0, 1], got " + number_text(min_visible));
  if (min_side < 1) fail("min_side must be >= 1, got " + number_text(min_side));
  if (!(size_noise > 0) || !std::isfinite(size_noise))
    fail("size_noise must be > 0, got " + number_text(size_noise));
  if (global_interval < 1)
    fail("global_interval must be >= 1, got " + number_text(global_interval));
  for (std::size_t i = 0; i < known.size(); ++i) {
    const KnownTarget& k = known[i];
    const cv::Rect2f& b = k.box;
    if (k.id <= 0) fail("known target ids must be > 0, got " + number_text(k.id));
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !(b.width >= 2) || !(b.height >= 2) ||
        !std::isfinite(b.width) || !std::isfinite(b.height))
      fail("known target " + number_text(k.id) + ": the box needs finite values and sides >= 2");
    for (std::size_t j = 0; j < i; ++j)
      if (known[j].id == k.id) fail("known target id " + number_text(k.id) + " given twice");
  }
}

// ------------------------------------------------------------------------------- Kalman filter

BoxFilter BoxFilter::start(const cv::Rect2f& box, cv::Point2f velocity) {
  BoxFilter f;
  f.x = {box.x + box.width / 2.0,
         box.y + box.height / 2.0,
         box.width,
         box.height,
         velocity.x,
         velocity.y,
         0,
         0};
  const double h = std::max(1.0, static_cast<double>(box.height));
  Eigen::Map<Mat8> p(f.p.data());
  p.setZero();
  const double sp = 2 * kStdPosition * h, sv = 10 * kStdVelocity * h;
  for (int i = 0; i < 4; ++i) {
    p(i, i) = sp * sp;
    p(i + 4, i + 4) = sv * sv;
  }
  return f;
}

void BoxFilter::predict() {
  Eigen::Map<Vec8> xs(x.data());
  Eigen::Map<Mat8> ps(p.data());
  static const Mat8 f = transition();
  const double h = std::max(1.0, xs(3));
  Mat8 q = Mat8::Zero();
  const double sp = kStdPosition * h, sv = kStdVelocity * h;
  for (int i = 0; i < 4; ++i) {
    q(i, i) = sp * sp;
    q(i + 4, i + 4) = sv * sv;
  }
  xs = f * xs;
  ps = f * ps * f.transpose() + q;
}

void BoxFilter::correct_box(const cv::Rect2f& box, double size_noise) {
  Eigen::Map<Vec8> xs(x.data());
  Eigen::Map<Mat8> ps(p.data());
  Eigen::Matrix<double, 4, 8> hm = Eigen::Matrix<double, 4, 8>::Zero();
  for (int i = 0; i < 4; ++i)
    hm(i, i) = 1;
  const double s = kStdPosition * std::max(1.0, xs(3));
  const double z_size = size_noise * std::max(1.0, xs(3));
  const Eigen::Vector4d diag(s * s, s * s, z_size * z_size, z_size * z_size);
  const Eigen::Matrix4d r = diag.asDiagonal();
  const Eigen::Vector4d z(box.x + box.width / 2.0, box.y + box.height / 2.0, box.width, box.height);
  const Eigen::Matrix4d sm = hm * ps * hm.transpose() + r;
  const Eigen::Matrix<double, 8, 4> k = ps * hm.transpose() * sm.inverse();
  xs += k * (z - hm * xs);
  ps = (Mat8::Identity() - k * hm) * ps;
}

void BoxFilter::correct_centre(cv::Point2f centre, double h) {
  Eigen::Map<Vec8> xs(x.data());
  Eigen::Map<Mat8> ps(p.data());
  Eigen::Matrix<double, 2, 8> hm = Eigen::Matrix<double, 2, 8>::Zero();
  hm(0, 0) = hm(1, 1) = 1;
  const double s = kStdLk * std::max(1.0, h);
  const Eigen::Matrix2d r = Eigen::Matrix2d::Identity() * s * s;
  const Eigen::Vector2d z(centre.x, centre.y);
  const Eigen::Matrix2d sm = hm * ps * hm.transpose() + r;
  const Eigen::Matrix<double, 8, 2> k = ps * hm.transpose() * sm.inverse();
  xs += k * (z - hm * xs);
  ps = (Mat8::Identity() - k * hm) * ps;
}

cv::Rect2f BoxFilter::box() const {
  const double w = std::max(1.0, x[2]), h = std::max(1.0, x[3]);
  return {static_cast<float>(x[0] - w / 2), static_cast<float>(x[1] - h / 2), static_cast<float>(w),
          static_cast<float>(h)};
}

cv::Point2f BoxFilter::velocity() const {
  return {static_cast<float>(x[4]), static_cast<float>(x[5])};
}

// ---------------------------------------------------------------------------------- the steps

TrackSet initial_tracks(const MultiTrackerParams& params) {
  TrackSet s;
  for (const KnownTarget& k : params.known) {
    Track t;
    t.id = k.id;
    t.known = true;
    t.box = k.box;
    t.filter = BoxFilter::start(k.box);
    s.tracks.push_back(t);
    s.next_id = std::max(s.next_id, k.id + 1);
  }
  return s;
}

std::vector<ObjectTile> plan_tiles(const TrackSet& state, const Foreground& fg,
                                   const MultiTrackerParams& params) {
  std::vector<ObjectTile> tiles;
  if (state.size.empty()) return tiles;
  const cv::Rect frame(0, 0, state.size.width, state.size.height);
  for (std::size_t i = 0; i < state.tracks.size(); ++i) {
    const Track& t = state.tracks[i];
    const cv::Rect2f& b = t.box;
    const cv::Point2f v = t.filter.velocity();
    const int m = params.margin;
    const cv::Rect region =
        cv::Rect(static_cast<int>(std::floor(b.x)) - m, static_cast<int>(std::floor(b.y)) - m,
                 static_cast<int>(std::ceil(b.width)) + 2 * m,
                 static_cast<int>(std::ceil(b.height)) + 2 * m) &
        frame;
    if (region.empty()) continue;
    const double area = std::max(1.0, static_cast<double>(b.area()));
    const int step =
        std::max(1, static_cast<int>(std::lround(std::sqrt(area / params.max_points))));
    const bool fg_only = !fg.empty() && !t.known ? fg.moving_share(b) >= 0.15 : false;
    // Where another object's box overlaps this one (a crossing), the shared pixels follow the
    // object in front: only this object's own pixels measure it.
    std::vector<cv::Rect2f> exclude;
    for (std::size_t j = 0; j < state.tracks.size(); ++j) {
      const Track& o = state.tracks[j];
      if (j == i || o.id == 0 || (o.box & b).area() <= 0) continue;
      exclude.push_back(o.box);
    }
    const int parts = (region.height + params.tile_rows - 1) / params.tile_rows;
    for (int k = 0; k < parts; ++k) {
      const int y0 = region.y + region.height * k / parts;
      const int y1 = region.y + region.height * (k + 1) / parts;
      tiles.push_back(
          {i, b, cv::Rect(region.x, y0, region.width, y1 - y0), v, step, fg_only, exclude});
    }
  }
  return tiles;
}

TileMotion measure_tile(const ObjectTile& tile, const flow::Pyramid& pyr_t,
                        const flow::Pyramid& pyr_t1, const Foreground& fg_t, flow::DenseLK& lk,
                        const MultiTrackerParams& params) {
  TileMotion out;
  out.track = tile.track;
  const cv::Size size = pyr_t.size();
  const cv::Rect frame(0, 0, size.width, size.height);
  const cv::Rect rows = tile.rows & frame;
  if (rows.empty()) return out;
  flow::FlowOptions fo;
  fo.region = rows;
  fo.initial_motion = tile.velocity;
  fo.context = params.lk_context;
  flow::FlowResult fwd;
  lk.calc(pyr_t, pyr_t1, fwd, fo);
  out.region = fwd.region;

  // The object's pixels in this tile: a grid over its box (its moving pixels when asked).
  const cv::Rect obj =
      cv::Rect(static_cast<int>(std::ceil(tile.box.x)), static_cast<int>(std::ceil(tile.box.y)),
               static_cast<int>(std::floor(tile.box.width)),
               static_cast<int>(std::floor(tile.box.height))) &
      fwd.region;
  std::vector<cv::Point> points;
  for (int y = obj.y + tile.step / 2; y < obj.br().y; y += tile.step) {
    for (int x = obj.x + tile.step / 2; x < obj.br().x; x += tile.step) {
      const cv::Point2f c(static_cast<float>(x), static_cast<float>(y));
      if (std::any_of(tile.exclude.begin(), tile.exclude.end(),
                      [&](const cv::Rect2f& r) { return r.contains(c); }))
        continue;
      if (tile.foreground_only &&
          fg_t.mask.at<std::uint8_t>(std::min(fg_t.mask.rows - 1, y / fg_t.scale),
                                     std::min(fg_t.mask.cols - 1, x / fg_t.scale)) == 0)
        continue;
      points.emplace_back(x, y);
    }
  }
  out.sampled = static_cast<int>(points.size());
  if (points.empty()) return out;
  std::vector<float> fx, fy;
  fx.reserve(points.size());
  fy.reserve(points.size());
  for (const cv::Point& p : points) {
    const cv::Vec2f f = fwd.flow.at<cv::Vec2f>(p - fwd.region.tl());
    fx.push_back(f[0]);
    fy.push_back(f[1]);
  }
  const cv::Point2f med(median(fx), median(fy));
  // Backward, around where the tile's object pixels went.
  const int pad = 4;
  const cv::Rect back = cv::Rect(obj.x + static_cast<int>(std::floor(med.x)) - pad,
                                 obj.y + static_cast<int>(std::floor(med.y)) - pad,
                                 obj.width + 2 * pad + 1, obj.height + 2 * pad + 1) &
                        frame;
  if (back.empty()) return out;
  flow::FlowOptions bo;
  bo.region = back;
  bo.initial_motion = -med;
  bo.context = params.lk_context;
  flow::FlowResult bwd;
  lk.calc(pyr_t1, pyr_t, bwd, bo);
  const float limit = static_cast<float>(params.fb_threshold);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const cv::Point2f f(fx[i], fy[i]);
    const cv::Point2f q = cv::Point2f(points[i]) + f - cv::Point2f(bwd.region.tl());
    if (!(q.x >= 0 && q.y >= 0 && q.x <= static_cast<float>(bwd.region.width - 1) &&
          q.y <= static_cast<float>(bwd.region.height - 1)))
      continue;
    const cv::Vec2f b = sample(bwd.flow, q);
    const float ex = f.x + b[0], ey = f.y + b[1];
    if (ex * ex + ey * ey < limit * limit) out.moves.push_back(f);
  }
  return out;
}

namespace {

// LK's measurement per object (the median motion of its pixels that passed the check), where it
// agrees with the filter; after each filter's prediction. guess: where each object is now.
struct LkMeasures {
  std::vector<char> ok;
  std::vector<cv::Rect2f> box, guess;
};

LkMeasures measure_lk(TrackSet& s, const std::vector<TileMotion>& motions,
                      const MultiTrackerParams& params) {
  const std::size_t n = s.tracks.size();
  std::vector<std::vector<float>> mx(n), my(n);
  std::vector<int> sampled(n, 0);
  for (const TileMotion& m : motions) {
    if (m.track >= n) continue;
    sampled[m.track] += m.sampled;
    for (const cv::Point2f& d : m.moves) {
      mx[m.track].push_back(d.x);
      my[m.track].push_back(d.y);
    }
  }
  LkMeasures lk{std::vector<char>(n, 0), std::vector<cv::Rect2f>(n), std::vector<cv::Rect2f>(n)};
  for (std::size_t i = 0; i < n; ++i) {
    Track& t = s.tracks[i];
    const cv::Rect2f before = t.box;
    t.filter.predict();
    lk.guess[i] = t.filter.box();
    const std::size_t good = mx[i].size();
    // LK's motion must agree with the motion the filter predicts: where another object passes
    // in front, the pixels of the region follow that one (an object does not turn back at once).
    const cv::Point2f v = t.filter.velocity();
    const double gate = std::max(params.lk_gate, params.lk_gate_share * before.height);
    const cv::Point2f m = good == 0 ? cv::Point2f() : cv::Point2f(median(mx[i]), median(my[i]));
    const bool agrees = good == 0 || t.age < 3 || std::hypot(m.x - v.x, m.y - v.y) <= gate;
    const bool valid = good >= 4 && static_cast<double>(good) >= params.min_inliers * sampled[i];
    // Its own pixels standing still: a ghost's box grows and moves, its pixels do not.
    if (valid) t.parked = std::hypot(m.x, m.y) < params.parked_motion ? t.parked + 1 : 0;
    if (valid && agrees) {
      lk.ok[i] = 1;
      cv::Rect2f& b = lk.box[i];
      b.width = lk.guess[i].width;
      b.height = lk.guess[i].height;
      b.x = before.x + before.width / 2 + m.x - lk.guess[i].width / 2;
      b.y = before.y + before.height / 2 + m.y - lk.guess[i].height / 2;
      lk.guess[i] = b;
    }
  }
  return lk;
}

// Blobs over several objects (they walk together or cross): no detection for any of them;
// LK keeps them apart. merged: per detection; in_merge: per object.
void find_merges(const TrackSet& s, const std::vector<cv::Rect2f>& guess,
                 const std::vector<Detection>& detections, const MultiTrackerParams& params,
                 std::vector<char>& merged, std::vector<char>& in_merge) {
  const std::size_t n = s.tracks.size(), nd = detections.size();
  merged.assign(nd, 0);
  in_merge.assign(n, 0);
  for (std::size_t j = 0; j < nd; ++j) {
    const cv::Rect2f& d = detections[j].box;
    std::vector<std::size_t> inside;
    for (std::size_t i = 0; i < n; ++i) {
      if (s.tracks[i].id == 0 || guess[i].area() <= 0) continue;
      if ((guess[i] & d).area() >= 0.5 * guess[i].area() &&
          d.area() >= params.merge_area * guess[i].area())
        inside.push_back(i);
    }
    // One of them that is most of the blob (IoU >= merge_own) is its object: the others pass in
    // front of or behind it, or are slices of it (cut off while it left its ghost). It takes the
    // detection; the others follow LK.
    bool owned = false;
    for (std::size_t i : inside)
      if (iou(guess[i], d) >= params.merge_own) owned = true;
    if (inside.size() >= 2 && !owned) {
      merged[j] = 1;
      for (std::size_t i : inside)
        in_merge[i] = 1;
    }
  }
}

// Optimal assignment of the detections outside merges to the objects outside merges: per
// object, its detection or -1.
std::vector<int> assign_detections(const TrackSet& s, const std::vector<cv::Rect2f>& guess,
                                   const std::vector<Detection>& detections,
                                   const std::vector<char>& still, const std::vector<char>& merged,
                                   const std::vector<char>& in_merge,
                                   const MultiTrackerParams& params) {
  const std::size_t n = s.tracks.size(), nd = detections.size();
  std::vector<std::size_t> rows, cols;
  for (std::size_t i = 0; i < n; ++i)
    if (!in_merge[i]) rows.push_back(i);
  for (std::size_t j = 0; j < nd; ++j)
    if (!merged[j]) cols.push_back(j);
  const double kForbidden = std::numeric_limits<double>::infinity();
  std::vector<double> cost(rows.size() * cols.size(), kForbidden);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const double o = iou(guess[rows[r]], detections[cols[c]].box);
      // Confirmed objects first: a tentative one takes a detection only if no confirmed one can.
      const double tentative = s.tracks[rows[r]].id == 0 ? 1.0 : 0.0;
      // A known target takes only a detection that is clearly it (its first frames' background
      // may hold it as a ghost).
      const double gate =
          s.tracks[rows[r]].known ? std::max(0.5, params.gate_iou) : params.gate_iou;
      // A still detection (a ghost) measures no object.
      if (still[cols[c]]) continue;
      if (o > gate) cost[r * cols.size() + c] = 1.0 - o + tentative;
    }
  }
  const Assignment assigned =
      solve_assignment(cost, static_cast<int>(rows.size()), static_cast<int>(cols.size()));
  std::vector<int> det_of(n, -1);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (assigned.row_to_col[r] < 0) continue;
    det_of[rows[r]] = static_cast<int>(cols[static_cast<std::size_t>(assigned.row_to_col[r])]);
  }
  return det_of;
}

// Whether `box` holds moving pixels: enough foreground, and enough of it changed lately (a
// ghost of the background model has none).
bool moves(const Foreground& fg, const cv::Rect2f& box, const MultiTrackerParams& params) {
  return fg.moving_share(box) >= params.min_moving && fg.changed_share(box) >= params.min_changed;
}

// Each object's filter corrected by its detection, else by LK where its box holds moving
// pixels; coasting otherwise. Returns whether a confirmed object is lost.
bool correct_tracks(TrackSet& s, bool first, const LkMeasures& lk, const std::vector<int>& det_of,
                    const std::vector<char>& in_merge, const Foreground& fg,
                    const std::vector<Detection>& detections, const MultiTrackerParams& params) {
  bool any_lost = false;
  for (std::size_t i = 0; i < s.tracks.size(); ++i) {
    Track& t = s.tracks[i];
    ++t.age;
    bool measured = false;
    if (first && t.known) {
      measured = true;  // given in this frame
    } else if (det_of[i] >= 0) {
      t.filter.correct_box(detections[static_cast<std::size_t>(det_of[i])].box, params.size_noise);
      measured = true;
      ++t.hits;
    } else {
      if (t.id == 0) t.hits = -1;  // a tentative object must be seen in consecutive frames
      if (lk.ok[i] && (t.known || moves(fg, lk.box[i], params))) {
        t.filter.correct_centre((lk.box[i].tl() + lk.box[i].br()) * 0.5f, lk.box[i].height);
        measured = true;
      }
    }
    if (!measured) {
      // Coasting: keep the motion, not a size that grows or shrinks with nothing to see.
      t.filter.x[6] = t.filter.x[7] = 0;
    } else if (in_merge[i] != 0) {
      // In a merge LK alone measures the centre, not the size: the size's speed fades (the
      // blob of several objects no longer feeds it; a vehicle that entered the frame has
      // stopped growing).
      t.filter.x[6] *= params.lk_size_decay;
      t.filter.x[7] *= params.lk_size_decay;
    }
    t.lost = measured ? 0 : t.lost + 1;
    t.box = t.filter.box();
    t.still = fg.empty() || moves(fg, t.box, params) ? 0 : t.still + 1;
    if (t.id != 0 && t.lost > 0) any_lost = true;
  }
  return any_lost;
}

// Duplicates (two objects on one box, or a fragment inside an older one, for 3 frames: the
// younger ends), deaths and confirmations.
void end_and_confirm(TrackSet& s, cv::Size size, const MultiTrackerParams& params) {
  const std::size_t n = s.tracks.size();
  for (std::size_t i = 0; i < n; ++i) {
    bool dup = false;
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j || s.tracks[j].id == 0 || s.tracks[i].id == 0) continue;
      const bool older = s.tracks[j].age > s.tracks[i].age ||
                         (s.tracks[j].age == s.tracks[i].age && s.tracks[j].id < s.tracks[i].id);
      // One box on the other, or a fragment inside one at least twice its size (a slice of
      // a vehicle the split cut off: it would make that vehicle's detection a merge of two).
      const cv::Rect2f& a = s.tracks[i].box;
      const cv::Rect2f& b = s.tracks[j].box;
      const bool fragment = (a & b).area() >= 0.8 * a.area() && 2 * a.area() < b.area();
      if (older && (iou(a, b) > 0.7 || fragment)) dup = true;
    }
    s.tracks[i].duplicate = dup ? s.tracks[i].duplicate + 1 : 0;
  }
  std::vector<Track> kept;
  kept.reserve(n);
  for (Track& t : s.tracks) {
    const cv::Rect2f inside = t.box & frame_rect(size);
    const bool ghost = !t.known && t.age < params.parked_age && t.parked >= params.parked_frames;
    const bool end = ghost || (t.id == 0 && t.hits < 0) || t.lost > params.max_lost ||
                     (!t.known && t.still >= params.still_frames) || t.duplicate >= 3 ||
                     visible_share(t.box, size) < params.min_visible ||
                     inside.width < static_cast<float>(params.min_side) ||
                     inside.height < static_cast<float>(params.min_side);
    if (end) {
      if (t.id != 0) ++s.ended;
      continue;
    }
    if (t.id == 0 && t.hits >= params.min_hits) {
      t.id = s.next_id++;
      ++s.born;
    }
    kept.push_back(t);
  }
  s.tracks = std::move(kept);
}

// Births: detections no object explains start tentative objects.
void add_births(TrackSet& s, const std::vector<Detection>& detections,
                const std::vector<char>& used, const std::vector<char>& still,
                const MultiTrackerParams& params) {
  for (std::size_t j = 0; j < detections.size(); ++j) {
    if (used[j] || still[j]) continue;
    const cv::Rect2f& d = detections[j].box;
    bool explained = false;
    for (const Track& t : s.tracks) {
      if (iou(t.box, d) > 0.3 || (t.box & d).area() >= 0.5 * d.area()) explained = true;
    }
    if (explained) continue;
    Track t;
    t.box = d;
    t.filter = BoxFilter::start(d);
    t.hits = 1;
    if (params.min_hits <= 1) {
      t.id = s.next_id++;
      ++s.born;
    }
    s.tracks.push_back(t);
  }
}

}  // namespace

TrackSet decide(const TrackSet& previous, long long index, cv::Size size,
                const std::vector<TileMotion>& motions, const Foreground& fg,
                const std::vector<Detection>& detections, const MultiTrackerParams& params,
                bool* global_frame) {
  TrackSet s = previous;
  s.frame = index;
  s.size = size;
  const LkMeasures lk = measure_lk(s, motions, params);
  std::vector<char> merged, in_merge;
  find_merges(s, lk.guess, detections, params, merged, in_merge);
  std::vector<char> still(detections.size(), 0);  // no changed pixels: a ghost
  for (std::size_t j = 0; j < detections.size(); ++j)
    still[j] = fg.changed_share(detections[j].box) < params.min_changed ? 1 : 0;
  const std::vector<int> det_of =
      assign_detections(s, lk.guess, detections, still, merged, in_merge, params);
  std::vector<char> used = merged;  // detections that start no object
  for (int j : det_of)
    if (j >= 0) used[static_cast<std::size_t>(j)] = 1;
  const bool any_lost =
      correct_tracks(s, previous.frame < 0, lk, det_of, in_merge, fg, detections, params);
  end_and_confirm(s, size, params);
  // Births on global frames: detections no object explains.
  const bool global =
      params.births && ((index % params.global_interval) == 0 || any_lost || s.tracks.empty());
  if (global) {
    ++s.global_activations;
    add_births(s, detections, used, still, params);
  }
  if (global_frame != nullptr) *global_frame = global;
  return s;
}

MotFrame report_frame(const TrackSet& state, const std::vector<TileMotion>& motions,
                      bool global_frame) {
  MotFrame f;
  f.index = state.frame;
  f.global = global_frame;
  f.born = state.born;
  f.ended = state.ended;
  f.global_activations = state.global_activations;
  for (const Track& t : state.tracks) {
    if (t.id == 0) continue;
    MotObject o;
    o.id = t.id;
    o.box = t.box;
    o.velocity = t.filter.velocity();
    o.lost = t.lost > 0;
    f.objects.push_back(o);
  }
  (void)motions;
  return f;
}

// ------------------------------------------------------------------------------- MultiTracker

struct MultiTracker::Impl {
  MultiTrackerParams params;
  MotionDetector detector;
  flow::DenseLK lk;
  TrackSet state;
  flow::Pyramid pyr_prev, pyr_cur;
  Foreground fg_prev;
  bool started = false;

  explicit Impl(const MultiTrackerParams& p)
      : params(p), detector(p.detector), lk(p.lk), state(initial_tracks(p)) {}
};

MultiTracker::MultiTracker(const MultiTrackerParams& params) {
  params.validate();
  impl_ = std::make_unique<Impl>(params);
}
MultiTracker::~MultiTracker() = default;
MultiTracker::MultiTracker(MultiTracker&&) noexcept = default;
MultiTracker& MultiTracker::operator=(MultiTracker&&) noexcept = default;

const MultiTrackerParams& MultiTracker::params() const {
  return impl_->params;
}
const TrackSet& MultiTracker::state() const {
  return impl_->state;
}

MotFrame MultiTracker::process(long long index, const cv::Mat& gray, const cv::Mat& image) {
  const auto start = std::chrono::steady_clock::now();
  Impl& s = *impl_;
  if (gray.empty() || gray.type() != CV_8UC1)
    throw Error("multi-object tracker: frames must be 8-bit gray");
  if (s.started && gray.size() != s.state.size)
    throw Error("multi-object tracker: frame size changed");
  flow::build_pyramid(gray, s.params.lk.levels, s.params.lk.sigma, s.pyr_cur);
  // Scene start: the flow of this frame back to the previous one (the global treatment's motion).
  flow::FlowResult back;
  if (s.started && s.detector.wants_flow()) {
    s.lk.calc(s.pyr_cur, s.pyr_prev, back);
  }
  Foreground fg =
      s.detector.observe(image.empty() ? gray : image, back.flow.empty() ? nullptr : &back);
  std::vector<Detection> detections = detect_objects(fg, s.params.detector);
  std::vector<TileMotion> motions;
  if (s.started) {
    // The motion split of the detections the objects say are wrong (after the scene start).
    const std::vector<std::size_t> which = split_candidates(s.state, detections, fg, s.params);
    if (!which.empty()) {
      std::vector<std::vector<cv::Rect2f>> parts;
      for (std::size_t j : which)
        parts.push_back(
            split_by_flow(detections[j].box, s.pyr_prev, s.pyr_cur, fg, s.lk, s.params));
      detections = apply_splits(detections, which, parts);
    }
    for (const ObjectTile& tile : plan_tiles(s.state, s.fg_prev, s.params))
      motions.push_back(measure_tile(tile, s.pyr_prev, s.pyr_cur, s.fg_prev, s.lk, s.params));
  } else {
    s.state.size = gray.size();
  }
  bool global = false;
  s.state = decide(s.state, index, gray.size(), motions, fg, detections, s.params, &global);
  s.started = true;
  std::swap(s.pyr_prev, s.pyr_cur);
  s.fg_prev = std::move(fg);
  MotFrame out = report_frame(s.state, motions, global);
  out.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace roiflow::tracking
