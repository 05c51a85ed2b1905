#include "tracking/local_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/local_tracker_impl.hpp"

namespace roiflow::tracking {

// The template matched at 2 * scale_steps + 1 scales around the box's size (2 * steps + 1 when
// `steps` >= 0), on the finest level where the object's shorter side is still at least
// match_side: NCC's cost grows with the template's area, and a few dozen pixels across are plenty
// to place and size a whole object.
Appearance LocalTracker::Impl::match(const cv::Mat& appearance, ScaledTemplates& sizes,
                                     const flow::Pyramid& pyr, cv::Point origin,
                                     const cv::Rect2f& b, double reach, int steps) const {
  const int scale_steps = steps >= 0 ? steps : params.scale_steps;
  const double shorter = std::min(b.width, b.height);
  const int level = coarsest_level_with(shorter, params.match_side, pyr.num_levels());
  const double f = 1.0 / (1 << level);
  const cv::Mat& image = pyr.levels[level];
  // `pyr` holds the part of the frame from `origin` (on the grid of every level): level-k
  // pixel i of the part is the frame's level-k pixel i + origin / 2^k.
  const cv::Point part_k(origin.x >> level, origin.y >> level);
  const cv::Size frame_k = flow::level_size(size, level);
  // Level-k pixel i sits at level-0 pixel i * 2^k: convert through pixel-centre coordinates.
  const cv::Point2f c0 = centre(b);
  const cv::Point2f ck((c0.x - 0.5f) * static_cast<float>(f) + 0.5f - static_cast<float>(part_k.x),
                       (c0.y - 0.5f) * static_cast<float>(f) + 0.5f - static_cast<float>(part_k.y));
  const double radius = reach * std::max(3.0, params.search * shorter * f);
  const double box_scale = std::sqrt(static_cast<double>(b.area()) / appearance.size().area());

  // The measured scale searches the whole window; the other scales only a few pixels around its
  // best position (a few percent of size change moves the best position by less than a pixel),
  // which keeps the cost of the scales near that of one.
  const int n = 2 * scale_steps + 1;
  const int middle = scale_steps;
  std::vector<TemplateMatch> found(n);
  std::vector<double> log_scale(n);
  cv::Rect middle_window;
  int best = -1;
  // A wide search (the target lost) meets lookalikes: of nearly equal matches, the one nearer the
  // prediction wins.
  MatchPrior prior;
  if (reach > 1.0) prior = {ck, radius, params.lost_prior};
  for (int k = 0; k < n; ++k) {
    const int j = k == 0 ? middle : (k <= middle ? k - 1 : k);
    const double ratio = std::pow(1.0 + params.scale_step, j - scale_steps);
    const double scale = box_scale * ratio * f;
    const bool near_middle = j != middle && found[middle].score > -1;
    const cv::Point2f at = near_middle ? centre(found[middle].box) : ck;
    const double pad = near_middle ? 2.0 : radius;
    const double half_w = 0.5 * appearance.cols * scale + pad;
    const double half_h = 0.5 * appearance.rows * scale + pad;
    const cv::Rect window =
        enclosing(cv::Rect2f(static_cast<float>(at.x - half_w), static_cast<float>(at.y - half_h),
                             static_cast<float>(2 * half_w), static_cast<float>(2 * half_h)));
    found[j] =
        match_template(image, sizes.at(appearance, scaled_size(appearance, scale)), window, prior);
    if (j == middle) middle_window = window & cv::Rect(cv::Point(), image.size());
    // The size really matched: match_template rounds the scaled template to whole pixels.
    log_scale[j] = found[j].score > -1 ? 0.5 * std::log(static_cast<double>(found[j].box.area()) /
                                                        (appearance.size().area() * f * f))
                                       : 0.0;
  }
  for (int j = 0; j < n; ++j) {
    if (found[j].score > -1 && (best < 0 || found[j].score > found[best].score)) best = j;
  }
  Appearance a;
  if (best < 0) return a;
  a.score = found[best].score;
  double log_s = log_scale[best];
  if (best > 0 && best + 1 < n && found[best - 1].score > -1 && found[best + 1].score > -1 &&
      log_scale[best - 1] < log_s && log_s < log_scale[best + 1]) {
    log_s = parabola_vertex(log_scale[best - 1], found[best - 1].score, log_s, found[best].score,
                            log_scale[best + 1], found[best + 1].score);
  }
  a.size_ratio = std::exp(log_s) / box_scale;
  const cv::Rect2f& m = found[best].box;
  // Whether the position search hit its window's edge: judged on the scale that searched the
  // whole window (the best one when the measured scale found nothing).
  const bool whole = found[middle].score > -1;
  const cv::Rect2f& mp = whole ? found[middle].box : m;
  const cv::Rect w = whole ? middle_window
                           : enclosing(cv::Rect2f(mp.x - static_cast<float>(radius),
                                                  mp.y - static_cast<float>(radius),
                                                  mp.width + 2 * static_cast<float>(radius),
                                                  mp.height + 2 * static_cast<float>(radius))) &
                                 cv::Rect(cv::Point(), image.size());
  // Edges of the frame (not of the part) bound the search: a match there is not at the edge.
  a.at_edge =
      (mp.x < w.x + 1.f && w.x + part_k.x > 0) || (mp.y < w.y + 1.f && w.y + part_k.y > 0) ||
      (mp.br().x > static_cast<float>(w.br().x) - 1.f && w.br().x + part_k.x < frame_k.width) ||
      (mp.br().y > static_cast<float>(w.br().y) - 1.f && w.br().y + part_k.y < frame_k.height);
  const cv::Point2f mk = centre(m) + cv::Point2f(part_k);
  a.centre = cv::Point2f(static_cast<float>((mk.x - 0.5) / f + 0.5),
                         static_cast<float>((mk.y - 0.5) / f + 0.5));
  return a;
}

// Median flow of the inliers, and the median ratio of their pairwise distances (pairs closer
// than a fifth of the box would make noisy ratios) as `scale`.
cv::Point2f LocalTracker::Impl::measure_motion(const LocalResult& r, double& scale) {
  // A non-rigid target (limbs that swing) or a thin one (a box mostly background): the pixels
  // that move unlike the background are the target's, when there are enough of them.
  if (params.segment && r.background_known && r.foreground > 0) {
    const float tol = foreground_tol(r.level);
    std::size_t kept = 0;
    for (int i : inliers) {
      const cv::Point2f d = to[i] - from[i] - r.background;
      if (d.dot(d) > tol * tol) inliers[kept++] = i;
    }
    inliers.resize(kept);
  }
  work_x.clear();
  work_y.clear();
  for (int i : inliers) {
    work_x.push_back(to[i].x - from[i].x);
    work_y.push_back(to[i].y - from[i].y);
  }
  const cv::Point2f motion(median(work_x), median(work_y));
  // Pixels that pass the check but move unlike the object (background inside the box, a shadow
  // sliding over it) would bias the scale: keep those whose motion is the median one up to what
  // a few percent of scale change allows at their distance from the centre.
  const cv::Point2f c_prev = centre(box);
  work_x.clear();
  consistent.clear();
  for (int i : inliers) {
    const cv::Point2f dev = to[i] - from[i] - motion;
    const cv::Point2f arm = from[i] - c_prev;
    const float tol = 1.f + kScaleTolerance * std::sqrt(arm.dot(arm));
    if (dev.dot(dev) <= tol * tol) consistent.push_back(i);
  }
  scale = 1.0;
  if (consistent.size() < 2) return motion;
  const float min_dist = std::max(2.f, 0.2f * std::min(box.width, box.height));
  const float min_dist2 = min_dist * min_dist;
  PairSampler pairs;
  const std::size_t tries = 2 * consistent.size();
  for (std::size_t k = 0; k < tries; ++k) {
    const int a = consistent[pairs.next() % consistent.size()];
    const int b = consistent[pairs.next() % consistent.size()];
    const cv::Point2f d0 = from[a] - from[b];
    const float n0 = d0.dot(d0);
    if (n0 < min_dist2) continue;
    const cv::Point2f d1 = to[a] - to[b];
    work_x.push_back(std::sqrt(d1.dot(d1) / n0));
  }
  if (work_x.size() >= 8) scale = median(work_x);
  return motion;
}

// The best match of the target's looks around `b`: the first look, which never drifts, is
// preferred; the recent one and the remembered ones take over while the object looks different
// (lighting, pose) and the first no longer matches well.
Appearance LocalTracker::Impl::look(const LocalFrame& in, const cv::Rect2f& b, double reach) {
  // The appearance search and the recent appearance's cut read frame t's part beyond LK's (the
  // whole part built so far, grown where they need more).
  cv::Rect need = match_need(templ, b, reach);
  if (!recent.empty()) need |= match_need(recent, b, reach);
  for (const cv::Mat& m : memory)
    need |= match_need(m, b, reach);
  cover(in, need);
  const cv::Point origin = next_part.rect.tl();
  Appearance a = match(templ, templ_sizes, view_next, origin, b, reach);
  if (a.score >= params.trust_appearance) return a;
  if (!recent.empty()) {
    const Appearance o = match(recent, recent_sizes, view_next, origin, b, reach);
    if (o.score > a.score) a = o;
  }
  for (std::size_t k = 0; k < memory.size() && a.score < params.trust_appearance; ++k) {
    const Appearance o = match(memory[k], memory_sizes[k], view_next, origin, b, reach);
    if (o.score > a.score) a = o;
  }
  return a;
}

// The first look at 17 sizes 5 % apart around `b` (0.68-1.48 of it; none whose shorter side
// falls below match_side, where a part of the target matches as well as the whole), each
// searched over the whole window, every scale_check_interval held frames. The step's own
// search sees only a few percent around the measured size, and the flow's scale measures the
// box's content: a box that took in background around the target grows with the background's
// motion, and a recent look cut from it then matches it at its wrong size. A size 10 % or more
// from the box's, not at the range's ends, that beats the box's own by scale_check_margin (and
// is a confident match) on two frames in a row moves the box half-way to it, in log size and in
// position. Returns whether it did.
bool LocalTracker::Impl::check_size(const LocalFrame& in, cv::Rect2f& b) {
  if (params.scale_check_interval == 0 || ++since_size_check < params.scale_check_interval) {
    return false;
  }
  since_size_check = 0;
  constexpr int kSteps = 8;
  constexpr double kStep = 1.05, kFar = 1.1;
  const double shorter = std::min(b.width, b.height);
  const int lowest = std::max(
      -kSteps,
      static_cast<int>(std::ceil(std::log(params.match_side / shorter) / std::log(kStep))));
  if (lowest >= 0) {
    size_pending = 0;
    return false;
  }
  const cv::Point2f c = centre(b);
  cover(in,
        match_need(templ, box_at(c, b.size() * static_cast<float>(std::pow(kStep, kSteps))), 1.0));
  const cv::Point origin = next_part.rect.tl();
  auto at_size = [&](int j) {
    return match(templ, wide_sizes, view_next, origin,
                 box_at(c, b.size() * static_cast<float>(std::pow(kStep, j))), 1.0, 0);
  };
  // The box's own size first: an NCC is at most 1, so above 1 - scale_check_margin no size can
  // beat it by the margin (and without one none is taken): the other sizes, most of the check's
  // cost, are not searched. The same outcome as searching them.
  const Appearance own_match = at_size(0);
  const double own = own_match.score;
  if (!(own > -1) || own + params.scale_check_margin > 1.0) {
    size_pending = 0;
    return false;
  }
  Appearance best;
  double best_ratio = 1;
  int best_j = 0;
  for (int j = lowest; j <= kSteps; ++j) {
    const double k = std::pow(kStep, j);
    const Appearance a = j == 0 ? own_match : at_size(j);
    if (a.score > best.score) {
      best = a;
      best_ratio = k * a.size_ratio;
      best_j = j;
    }
  }
  int dir = 0;
  if (own > -1 && best.score >= params.confident_appearance && best_j > lowest && best_j < kSteps &&
      best.score >= own + params.scale_check_margin &&
      (best_ratio >= kFar || best_ratio <= 1 / kFar)) {
    dir = best_ratio > 1 ? 1 : -1;
  }
  // A new direction is checked again on the next frame before it is taken.
  if (dir == 0 || dir != size_pending) {
    size_pending = dir;
    if (dir != 0) since_size_check = params.scale_check_interval - 1;
    return false;
  }
  size_pending = 0;
  const float k = static_cast<float>(std::sqrt(best_ratio));
  b = box_at(0.5f * (c + best.centre), b.size() * k);
  return true;
}

// The appearance memory follows the target slowly and only from confident frames: the recent
// look every template_interval of them, a long-term one every memory_interval (the oldest
// forgotten beyond `memory`).
void LocalTracker::Impl::remember(const LocalFrame& in, double appearance, double inlier_share) {
  ++since_recent;
  ++since_memory;
  if (appearance < params.confident_appearance || inlier_share < 0.5) return;
  if (since_recent >= params.template_interval) {
    cover(in, grown(enclosing(box), 2));
    cut(view_next, next_part.rect.tl(), box, recent);
    recent_sizes.clear();
    since_recent = 0;
  }
  if (params.memory > 0 && since_memory >= params.memory_interval && !recent.empty()) {
    if (static_cast<int>(memory.size()) >= params.memory) {
      memory.erase(memory.begin());
      memory_sizes.erase(memory_sizes.begin());
    }
    memory.push_back(recent.clone());
    memory_sizes.emplace_back();
    since_memory = 0;
  }
}

double LocalTracker::Impl::verify(const LocalFrame& in, const cv::Rect2f& b) {
  check_frame(in);
  if (in.gray.size() != size) throw Error("local tracker: verify() on a frame of another size");
  PartPyramid part;
  cv::Rect need = match_need(templ, b, 1.0);
  if (!recent.empty()) need |= match_need(recent, b, 1.0);
  for (const cv::Mat& m : memory)
    need |= match_need(m, b, 1.0);
  build(in.gray, in.pyramid, part_for(need & frame_rect()), part);
  flow::Pyramid v;
  view(part, part.rect, levels, v);
  double best = match(templ, templ_sizes, v, part.rect.tl(), b, 1.0).score;
  if (!recent.empty()) {
    best = std::max(best, match(recent, recent_sizes, v, part.rect.tl(), b, 1.0).score);
  }
  for (std::size_t k = 0; k < memory.size(); ++k)
    best = std::max(best, match(memory[k], memory_sizes[k], v, part.rect.tl(), b, 1.0).score);
  return best;
}

}  // namespace roiflow::tracking
