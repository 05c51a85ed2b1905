// Internal to the local treatment (tracking/local_tracker*.cpp): the geometry and pyramid-part
// helpers its steps share, and LocalTracker::Impl, the state one tracked object carries from frame
// to frame. Split by concern: local_tracker.cpp (the step and the public interface),
// local_tracker_match.cpp (appearance matching, motion and scale from the flow),
// local_tracker_checks.cpp (self-awareness: the checks that declare a measurement impossible).
//
//   // inside src/tracking only
//   #include "tracking/local_tracker_impl.hpp"
//   const cv::Rect r = roiflow::tracking::detail::enclosing(cv::Rect2f(0.5f, 0.5f, 3.f, 2.f));
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/local_tracker.hpp"
#include "tracking/select_impl.hpp"
#include "tracking/template_search.hpp"

namespace roiflow::tracking {
namespace detail {

inline cv::Point2f centre(const cv::Rect2f& r) {
  return {r.x + 0.5f * r.width, r.y + 0.5f * r.height};
}

inline cv::Rect2f box_at(cv::Point2f c, cv::Size2f s) {
  return {c.x - 0.5f * s.width, c.y - 0.5f * s.height, s.width, s.height};
}

// Smallest integer rectangle holding `r`.
inline cv::Rect enclosing(const cv::Rect2f& r) {
  const int x0 = static_cast<int>(std::floor(r.x));
  const int y0 = static_cast<int>(std::floor(r.y));
  const int x1 = static_cast<int>(std::ceil(r.x + r.width));
  const int y1 = static_cast<int>(std::ceil(r.y + r.height));
  return {x0, y0, x1 - x0, y1 - y0};
}

// `r` grown by `m` pixels on every side.
inline cv::Rect grown(const cv::Rect& r, int m) {
  return {r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m};
}

// Bilinear sample of a CV_32FC2 field at (x, y), false outside its last full 2x2 cell.
inline bool sample(const cv::Mat& field, float x, float y, cv::Vec2f& out) {
  if (!(x >= 0.f && y >= 0.f)) return false;
  const int ix = static_cast<int>(x);
  const int iy = static_cast<int>(y);
  if (ix + 1 >= field.cols || iy + 1 >= field.rows) return false;
  const float ax = x - static_cast<float>(ix);
  const float ay = y - static_cast<float>(iy);
  const cv::Vec2f* r0 = field.ptr<cv::Vec2f>(iy) + ix;
  const cv::Vec2f* r1 = field.ptr<cv::Vec2f>(iy + 1) + ix;
  out = (1.f - ay) * ((1.f - ax) * r0[0] + ax * r0[1]) + ay * ((1.f - ax) * r1[0] + ax * r1[1]);
  return true;
}

// Vertex abscissa of the parabola through three points, clamped to [x0, x2]; x1 when the three
// do not make a maximum.
inline double parabola_vertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double d01 = (y1 - y0) / (x1 - x0);
  const double d12 = (y2 - y1) / (x2 - x1);
  const double curvature = (d12 - d01) / (x2 - x0);
  if (!(curvature < 0.0) || !std::isfinite(curvature)) return x1;
  const double vertex = 0.5 * (x0 + x1) - d01 / (2.0 * curvature);
  return std::clamp(vertex, x0, x2);
}

// Deterministic pair sampling for the scale estimate (xorshift32: the same pairs everywhere).
class PairSampler {
 public:
  std::uint32_t next() {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }

 private:
  std::uint32_t state_ = 2463534242u;
};

// Relative size change per frame that the motion-consistency test of the scale estimate allows.
inline constexpr float kScaleTolerance = 0.05f;
// The largest size change accepted between two frames.
inline constexpr double kMaxScaleChange = 1.25;

// The appearance at `b` (frame pixels) in level 0 of `pyr`, the pyramid of the part of the
// frame whose top-left pixel is `origin`, sub-pixel placed (pixel i covers [i, i + 1), so the
// box's centre is at pixel coordinate c - 0.5).
inline void cut(const flow::Pyramid& pyr, cv::Point origin, const cv::Rect2f& b, cv::Mat& out) {
  const cv::Point2f c = centre(b) - cv::Point2f(origin);
  cv::getRectSubPix(
      pyr.levels[0],
      cv::Size(static_cast<int>(std::lround(b.width)), static_cast<int>(std::lround(b.height))),
      cv::Point2f(c.x - 0.5f, c.y - 0.5f), out, CV_32F);
}

// Level `l` of a pyramid part (`rect` of the frame at level 0, origin on the coarsest level's
// grid) is the rectangle `rect` / 2^l of the frame's level l; sizes as pyrDown makes them.
inline cv::Rect level_rect(const cv::Rect& rect, int l) {
  return {cv::Point(rect.x >> l, rect.y >> l), flow::level_size(rect.size(), l)};
}

// A pyramid of part of a frame: `rect` (level-0 pixels) and its levels.
struct PartPyramid {
  cv::Rect rect;
  flow::Pyramid pyr;
};

// The first `levels` levels of `part` restricted to `want` (inside part.rect, both origins on
// the grid of those levels): views, no copy.
inline void view(const PartPyramid& part, const cv::Rect& want, int levels, flow::Pyramid& out) {
  out.levels.resize(std::min(part.pyr.levels.size(), static_cast<std::size_t>(levels)));
  for (std::size_t l = 0; l < out.levels.size(); ++l) {
    const int li = static_cast<int>(l);
    const cv::Rect have = level_rect(part.rect, li);
    const cv::Rect w = level_rect(want, li);
    out.levels[l] = part.pyr.levels[l](cv::Rect(w.tl() - have.tl(), w.size()));
  }
}

// The coarsest of levels 0 .. levels - 1 where a side of `side` level-0 pixels still measures
// at least `least` pixels.
inline int coarsest_level_with(double side, double least, int levels) {
  int level = 0;
  while (level + 1 < levels && side / (2 << level) >= least)
    ++level;
  return level;
}

// A template at the sizes it was matched at: the object's size changes little from frame to
// frame, so the same few sizes come back and need no resizing again.
// Each is kept prepared for the direct NCC.
class ScaledTemplates {
 public:
  const DirectTemplate& at(const cv::Mat& templ, cv::Size size) {
    for (const auto& [s, m] : sizes_) {
      if (s == size) return m;
    }
    // The oldest size goes first (clearing them all made the wide size check's 17 sizes, and
    // the step's 11 as the box's size drifts, be resized again and again).
    if (sizes_.size() >= kKept) sizes_.erase(sizes_.begin());
    sizes_.emplace_back(size, DirectTemplate(resize_template(templ, size)));
    return sizes_.back().second;
  }
  void clear() { sizes_.clear(); }

 private:
  static constexpr std::size_t kKept = 24;
  std::vector<std::pair<cv::Size, DirectTemplate>> sizes_;
};

// The best appearance match around a box: centre and size in level-0 pixels, and its NCC.
struct Appearance {
  double score = -1;
  cv::Point2f centre;
  double size_ratio = 1;  // matched size / the box's size
  bool at_edge = false;   // the best match touches the search window inside the image: the
                          // real peak may lie beyond it
};

}  // namespace detail

// Internal header: the steps' files share these names.
using namespace detail;  // NOLINT(google-build-using-namespace)

struct LocalTracker::Impl {
  LocalTrackerParams params;
  const Executor* executor = nullptr;
  cv::Size size;         // of the frames; empty before start()
  int frame_levels = 1;  // effective levels of a whole-frame pyramid (lk.levels) at that size
  int levels = 1;        // levels of this step's pyramid parts (more when LK runs coarser)
  cv::Mat prev;          // frame t-1's gray image
  std::shared_ptr<const flow::Pyramid> prev_whole;  // its whole pyramid (whole_frame mode)
  PartPyramid prev_part;  // the part of frame t-1's pyramid built so far (may be empty)
  PartPyramid next_part;  // buffers for frame t's part
  cv::Rect2f box;
  cv::Point2f velocity;
  cv::Mat templ;   // CV_32FC1 appearance at level 0, cut at the box given to start()
  cv::Mat recent;  // the same, cut at a recent confidently tracked box (empty until then)
  ScaledTemplates templ_sizes, recent_sizes;
  int since_recent = 0;
  std::vector<cv::Mat> memory;  // earlier confident looks (long-term memory), oldest first
  std::vector<ScaledTemplates> memory_sizes;
  int since_memory = 0;
  // The wide size check (check_size): the first look at sizes far from the box's.
  ScaledTemplates wide_sizes;
  int since_size_check = 0;
  int size_pending = 0;  // the direction (+1 larger, -1 smaller) the last check asked for, 0 none
  // Self-awareness (local_tracker_checks.cpp).
  bool lost = false;    // the last step left the target lost: the box coasts
  int lost_frames = 0;  // frames lost in a row
  double moving = 0;    // recent speed relative to the background (running mean)
  bool built = false;   // frame t's part is in next_part (this step)

  // Buffers reused from frame to frame: the forward and backward LK keep their workspaces (a
  // dense_flow call would allocate and zero one every time).
  flow::Pyramid view_prev, view_cur, view_next;
  flow::DenseLK forward_lk, backward_lk;
  flow::FlowResult forward;
  flow::FlowResult backward;
  std::vector<cv::Point2f> from, to;
  std::vector<float> conf, work_x, work_y;
  std::vector<int> inliers, consistent;

  cv::Rect frame_rect() const { return {cv::Point(), size}; }

  void check_frame(const LocalFrame& f) const {
    if (f.gray.empty() || f.gray.type() != CV_8UC1) {
      throw Error(
          "local tracker: frame must be 8-bit gray, got " +
          (f.gray.empty() ? std::string("an empty image") : cv::typeToString(f.gray.type())));
    }
    if (f.pyramid &&
        (f.pyramid->size() != f.gray.size() || f.pyramid->num_levels() < frame_levels)) {
      throw Error("local tracker: the pyramid given with a frame is not that frame's");
    }
  }

  void place(const LocalFrame& f, const cv::Rect2f& b) {
    if (!(std::isfinite(b.x) && std::isfinite(b.y) && b.width >= 2 && b.height >= 2 &&
          std::isfinite(b.width) && std::isfinite(b.height))) {
      throw Error("local tracker: box (" + number_text(b.x) + ", " + number_text(b.y) + ", " +
                  number_text(b.width) + " x " + number_text(b.height) +
                  ") must be finite with sides of at least 2 pixels");
    }
    if (f.gray.empty()) throw Error("local tracker: empty frame");
    const cv::Size frame_size = f.gray.size();
    const cv::Rect inside = enclosing(b) & cv::Rect(cv::Point(), frame_size);
    if (inside.width < 2 || inside.height < 2) {
      throw Error("local tracker: box (" + number_text(b.x) + ", " + number_text(b.y) + ", " +
                  number_text(b.width) + " x " + number_text(b.height) +
                  ") leaves nothing inside the " + number_text(frame_size.width) + " x " +
                  number_text(frame_size.height) + " frame");
    }
    size = frame_size;
    frame_levels = flow::effective_levels(size, params.lk.levels);
    levels = frame_levels;
    check_frame(f);
    prev = f.gray;
    prev_whole = params.whole_frame ? f.pyramid : nullptr;
    prev_part.rect = cv::Rect();
    box = b;
    velocity = {0.f, 0.f};
    lost = false;
    lost_frames = 0;
    moving = 0;
    since_size_check = 0;
    size_pending = 0;
  }

  // `r` grown to the coarsest level's pixel grid and to at least kMinLevelSide pixels there
  // (so that a part keeps every level), clipped to the frame.
  cv::Rect aligned(const cv::Rect& r) const {
    const int a = 1 << (levels - 1);
    const cv::Rect frame = frame_rect();
    auto floor_to = [a](int v) { return v >= 0 ? v / a * a : -((-v + a - 1) / a) * a; };
    int x0 = floor_to(r.x), y0 = floor_to(r.y);
    int x1 = -floor_to(-(r.x + r.width)), y1 = -floor_to(-(r.y + r.height));
    const int least = flow::kMinLevelSide * a;
    auto grow = [&](int& lo, int& hi, int extent) {
      if (hi - lo >= least) return;
      const int more = (least - (hi - lo) + 2 * a - 1) / (2 * a) * a;
      lo -= more;
      hi += more;
      if (lo < 0) {
        hi -= lo;
        lo = 0;
      }
      if (hi > extent) {
        lo = std::max(0, floor_to(lo - (hi - extent)));
        hi = extent;
      }
    };
    grow(x0, x1, frame.width);
    grow(y0, y1, frame.height);
    return cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & frame;
  }

  // Builds `out` over `rect` of a frame: the whole pyramid when `rect` is the frame and one with
  // enough levels was given, else the pyramid of gray(rect).
  void build(const cv::Mat& gray, const std::shared_ptr<const flow::Pyramid>& whole,
             const cv::Rect& rect, PartPyramid& out) const {
    out.rect = rect;
    if (whole && rect == frame_rect() && whole->num_levels() >= levels) {
      out.pyr = *whole;
      return;
    }
    // Never write into a buffer someone else still shares (a whole pyramid, a view).
    for (cv::Mat& level : out.pyr.levels) {
      if (level.u != nullptr && level.u->refcount > 1) level.release();
    }
    flow::build_pyramid_part(gray, rect, levels, params.lk.sigma, out.pyr);
  }

  // Pixels at a part's edges where its values differ from the whole frame's (the smoothing and
  // pyrDown there see a replicated border instead of the frame).
  int border() const { return 3 << (levels - 1); }

  // `r` grown by the border and aligned: the part whose values equal the whole frame's over `r`.
  cv::Rect part_for(const cv::Rect& r) const { return aligned(grown(r, border())); }

  // The part of the frame LK reads in a step: its footprint over the region and a margin for the
  // velocity. The appearance search reads around the measured box, which lies in the region, so
  // a step covers it (and rarely has to grow the part: match_need) only once the flow has placed
  // the box; a margin for a box that may have moved anywhere in the region made parts ~1.4x
  // larger.
  cv::Rect step_part(const cv::Rect& region, int lk_level) const {
    if (params.whole_frame) return frame_rect();
    flow::FlowOptions o;
    o.region = region;
    o.context = params.lk_context;
    o.finest_level = lk_level;
    const cv::Rect need = flow::flow_footprint(size, params.lk, o);
    const int motion = static_cast<int>(std::ceil(std::hypot(velocity.x, velocity.y)));
    return part_for(grown(need, motion));
  }

  // What match() of `appearance` around `b` reads, level-0 pixels: every scale's search window on
  // the match level (the other scales' windows lie a few pixels around the measured scale's best
  // position), with a pixel of that level for each rounding.
  cv::Rect match_need(const cv::Mat& appearance, const cv::Rect2f& b, double reach) const {
    const double shorter = std::min(b.width, b.height);
    const int level = coarsest_level_with(shorter, params.match_side, levels);
    const double k = 1 << level;
    const double radius = reach * std::max(3.0, params.search * shorter / k);  // level pixels
    const double grow = std::pow(1.0 + params.scale_step, params.scale_steps) *
                        std::sqrt(static_cast<double>(b.area()) / appearance.size().area());
    const double half_w = 0.5 * appearance.cols * grow + (radius + 5.0) * k;
    const double half_h = 0.5 * appearance.rows * grow + (radius + 5.0) * k;
    const cv::Point2f c = centre(b);
    return enclosing(cv::Rect2f(c.x - static_cast<float>(half_w), c.y - static_cast<float>(half_h),
                                static_cast<float>(2 * half_w), static_cast<float>(2 * half_h)));
  }

  // The coarsest level where the object's shorter side still spans lk_patches LK patches (0 in
  // whole_frame mode), and the levels a step's pyramid parts then need.
  int lk_level() const {
    if (params.whole_frame || params.lk_patches <= 0) return 0;
    return coarsest_level_with(std::min(box.width, box.height), params.lk_patches * params.lk.patch,
                               flow::kMaxLevels);
  }
  int part_levels(int lk_level) const {
    flow::FlowOptions o;
    o.finest_level = lk_level;
    return flow::flow_pyramid_levels(size, params.lk, o);
  }

  // Grows frame t's part (rebuilt, rarely) until its values equal the whole frame's over `need`.
  void cover(const LocalFrame& in, const cv::Rect& need) {
    const cv::Rect want = part_for(need & frame_rect());
    if ((next_part.rect & want) == want) return;
    view_cur.levels.clear();
    view_next.levels.clear();
    build(in.gray, in.pyramid, aligned(next_part.rect | want), next_part);
    view(next_part, next_part.rect, levels, view_next);
  }

  // One step, in the order track() runs them (local_tracker.cpp).
  cv::Rect region_for(const cv::Rect2f& predicted_box, int lk_level) const;
  cv::Point build_step(const LocalFrame& in, const cv::Rect& region, int lk_level);
  cv::Point2f sample_object(const cv::Rect& object, const cv::Rect& region, double& texture);
  double backward_check(const cv::Rect& object, cv::Point2f rough, cv::Point origin,
                        const cv::Rect& part, int lk_level);
  Appearance look(const LocalFrame& in, const cv::Rect2f& b, double reach);
  void remember(const LocalFrame& in, double appearance, double inliers);
  void advance(const LocalFrame& in);
  LocalResult& lose(LocalResult& r, LostReason why, const cv::Rect2f& predicted_box,
                    const LocalFrame& in);
  // Self-awareness (local_tracker_checks.cpp).
  void measure_background(LocalResult& r, const cv::Rect2f& b) const;
  LostReason check_flow(const LocalResult& r, double raw_scale) const;
  LostReason check_state(const LocalResult& r, cv::Point2f motion, const cv::Rect2f& next) const;
  void learn_motion(const LocalResult& r, cv::Point2f motion);
  double verify(const LocalFrame& in, const cv::Rect2f& b);
  // Pixels (level 0) by which a flow must differ from the background's to be the target's.
  float foreground_tol(int lk_level) const {
    return static_cast<float>(params.foreground_tolerance * (1 << lk_level));
  }

  Appearance match(const cv::Mat& appearance, ScaledTemplates& sizes, const flow::Pyramid& pyr,
                   cv::Point origin, const cv::Rect2f& b, double reach, int steps = -1) const;
  bool check_size(const LocalFrame& in, cv::Rect2f& b);
  cv::Point2f measure_motion(const LocalResult& r, double& scale);
  LocalResult track(const LocalFrame& frame);
};

}  // namespace roiflow::tracking
