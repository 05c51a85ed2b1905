#include "stages/local_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "core/error.hpp"
#include "core/text.hpp"
#include "stages/template_search.hpp"

namespace roiflow::stages {
namespace {

void check_range(const char* name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    throw Error(std::string("local tracker: ") + name + " must be in [" + number_text(lo) + ", " +
                number_text(hi) + "], got " + number_text(value));
  }
}

cv::Point2f centre(const cv::Rect2f& r) {
  return {r.x + 0.5f * r.width, r.y + 0.5f * r.height};
}

cv::Rect2f box_at(cv::Point2f c, cv::Size2f s) {
  return {c.x - 0.5f * s.width, c.y - 0.5f * s.height, s.width, s.height};
}

// Smallest integer rectangle holding `r`.
cv::Rect enclosing(const cv::Rect2f& r) {
  const int x0 = static_cast<int>(std::floor(r.x));
  const int y0 = static_cast<int>(std::floor(r.y));
  const int x1 = static_cast<int>(std::ceil(r.x + r.width));
  const int y1 = static_cast<int>(std::ceil(r.y + r.height));
  return {x0, y0, x1 - x0, y1 - y0};
}

// `r` grown by `m` pixels on every side.
cv::Rect grown(const cv::Rect& r, int m) {
  return {r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m};
}

// Median by partial sort; reorders `v`, which must not be empty.
float median(std::vector<float>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Bilinear sample of a CV_32FC2 field at (x, y), false outside its last full 2x2 cell.
bool sample(const cv::Mat& field, float x, float y, cv::Vec2f& out) {
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
double parabola_vertex(double x0, double y0, double x1, double y1, double x2, double y2) {
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
constexpr float kScaleTolerance = 0.05f;
// The largest size change accepted between two frames.
constexpr double kMaxScaleChange = 1.25;

// The appearance at `b` (frame pixels) in level 0 of `pyr`, the pyramid of the part of the
// frame whose top-left pixel is `origin`, sub-pixel placed (pixel i covers [i, i + 1), so the
// box's centre is at pixel coordinate c - 0.5).
void cut(const flow::Pyramid& pyr, cv::Point origin, const cv::Rect2f& b, cv::Mat& out) {
  const cv::Point2f c = centre(b) - cv::Point2f(origin);
  cv::getRectSubPix(
      pyr.levels[0],
      cv::Size(static_cast<int>(std::lround(b.width)), static_cast<int>(std::lround(b.height))),
      cv::Point2f(c.x - 0.5f, c.y - 0.5f), out, CV_32F);
}

// Level `l` of a pyramid part (`rect` of the frame at level 0, origin on the coarsest level's
// grid) is the rectangle `rect` / 2^l of the frame's level l; sizes as pyrDown makes them.
cv::Rect level_rect(const cv::Rect& rect, int l) {
  return {cv::Point(rect.x >> l, rect.y >> l), flow::level_size(rect.size(), l)};
}

// A pyramid of part of a frame: `rect` (level-0 pixels) and its levels.
struct PartPyramid {
  cv::Rect rect;
  flow::Pyramid pyr;
};

// The first `levels` levels of `part` restricted to `want` (inside part.rect, both origins on
// the grid of those levels): views, no copy.
void view(const PartPyramid& part, const cv::Rect& want, int levels, flow::Pyramid& out) {
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
int coarsest_level_with(double side, double least, int levels) {
  int level = 0;
  while (level + 1 < levels && side / (2 << level) >= least)
    ++level;
  return level;
}

// A template at the sizes it was matched at: the object's size changes little from frame to
// frame, so the same few sizes come back and need no resizing again.
class ScaledTemplates {
 public:
  const cv::Mat& at(const cv::Mat& templ, cv::Size size) {
    for (const auto& [s, m] : sizes_) {
      if (s == size) return m;
    }
    if (sizes_.size() >= kKept) sizes_.clear();
    sizes_.emplace_back(size, resize_template(templ, size));
    return sizes_.back().second;
  }
  void clear() { sizes_.clear(); }

 private:
  static constexpr std::size_t kKept = 16;
  std::vector<std::pair<cv::Size, cv::Mat>> sizes_;
};

// The best appearance match around a box: centre and size in level-0 pixels, and its NCC.
struct Appearance {
  double score = -1;
  cv::Point2f centre;
  double size_ratio = 1;  // matched size / the box's size
  bool at_edge = false;   // the best match touches the search window inside the image: the
                          // real peak may lie beyond it
};

}  // namespace

void LocalTrackerParams::validate() const {
  check_range("roi", roi, 8, 4096);
  lk.validate();
  check_range("max_points", max_points, 16, 1e6);
  check_range("lk_context", lk_context, -1, 1000);
  check_range("lk_patches", lk_patches, 0, 100);
  check_range("fb_levels", fb_levels, 1, flow::kMaxLevels);
  if (!(fb_threshold > 0) || !std::isfinite(fb_threshold)) {
    throw Error("local tracker: fb_threshold must be > 0, got " + number_text(fb_threshold));
  }
  if (!(min_inliers >= 0 && min_inliers < 1)) {
    throw Error("local tracker: min_inliers must be in [0, 1), got " + number_text(min_inliers));
  }
  if (!(min_texture >= 0) || !std::isfinite(min_texture)) {
    throw Error("local tracker: min_texture must be >= 0, got " + number_text(min_texture));
  }
  if (!(min_appearance >= -1 && min_appearance < 1)) {
    throw Error("local tracker: min_appearance must be in [-1, 1), got " +
                number_text(min_appearance));
  }
  check_range("trust_appearance", trust_appearance, min_appearance, 1);
  check_range("appearance_weight", appearance_weight, 0, 1);
  if (!(search > 0 && search <= 2)) {
    throw Error("local tracker: search must be in (0, 2], got " + number_text(search));
  }
  if (!(scale_step > 0 && scale_step < 0.5)) {
    throw Error("local tracker: scale_step must be in (0, 0.5), got " + number_text(scale_step));
  }
  check_range("scale_steps", scale_steps, 0, 10);
  check_range("match_side", match_side, 8, 256);
  check_range("template_interval", template_interval, 1, 1e9);
  check_range("velocity_gain", velocity_gain, 0, 1);
}

const char* to_string(LostReason reason) {
  switch (reason) {
    case LostReason::Found:
      return "found";
    case LostReason::FewInliers:
      return "few-inliers";
    case LostReason::LowTexture:
      return "low-texture";
    case LostReason::Appearance:
      return "appearance";
    case LostReason::LeftRegion:
      return "left-region";
  }
  return "?";
}

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

  // Buffers reused from frame to frame.
  flow::Pyramid view_prev, view_cur, view_next;
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

  Appearance match(const cv::Mat& appearance, ScaledTemplates& sizes, const flow::Pyramid& pyr,
                   cv::Point origin, const cv::Rect2f& b, double reach) const;
  cv::Point2f measure_motion(double& scale);
  LocalResult track(const LocalFrame& frame);
};

// The template matched at 2 * scale_steps + 1 scales around the box's size, on the finest level
// where the object's shorter side is still at least match_side: NCC's cost grows with the
// template's area, and a few dozen pixels across are plenty to place and size a whole object.
Appearance LocalTracker::Impl::match(const cv::Mat& appearance, ScaledTemplates& sizes,
                                     const flow::Pyramid& pyr, cv::Point origin,
                                     const cv::Rect2f& b, double reach) const {
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
  const int n = 2 * params.scale_steps + 1;
  const int middle = params.scale_steps;
  std::vector<TemplateMatch> found(n);
  std::vector<double> log_scale(n);
  cv::Rect middle_window;
  int best = -1;
  TemplateSearchParams tp;
  tp.coarse_side = 0;
  tp.scales = {1.0};  // the template comes resized
  for (int k = 0; k < n; ++k) {
    const int j = k == 0 ? middle : (k <= middle ? k - 1 : k);
    const double ratio = std::pow(1.0 + params.scale_step, j - params.scale_steps);
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
        match_template(image, sizes.at(appearance, scaled_size(appearance, scale)), window, tp);
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

LocalResult LocalTracker::Impl::track(const LocalFrame& in) {
  if (prev.empty()) throw Error("local tracker: track() before start()");
  if (in.gray.size() != size) {
    throw Error("local tracker: frame is " + number_text(in.gray.cols) + " x " +
                number_text(in.gray.rows) + ", the previous one was " + number_text(size.width) +
                " x " + number_text(size.height));
  }
  check_frame(in);
  const cv::Rect frame = frame_rect();
  const cv::Rect2f predicted_box(box.x + velocity.x, box.y + velocity.y, box.width, box.height);

  LocalResult r;
  r.velocity = velocity;
  bool built = false;  // frame t's part is in next_part
  // Frame t becomes frame t-1 of the next step, with the part of its pyramid built so far.
  auto advance = [&] {
    prev = in.gray;
    prev_whole = params.whole_frame ? in.pyramid : nullptr;
    if (built) {
      std::swap(prev_part, next_part);
    } else {
      prev_part.rect = cv::Rect();
    }
  };
  auto lose = [&](LostReason why) {
    r.lost = true;
    r.reason = why;
    r.box = predicted_box;
    box = predicted_box;
    advance();
    return r;
  };

  // The region holds the object now and where it is predicted next, at least roi x roi.
  if (params.whole_frame) {
    r.region = frame;
  } else {
    cv::Rect span = enclosing(box) | enclosing(predicted_box);
    const int grow_x = std::max(0, params.roi - span.width);
    const int grow_y = std::max(0, params.roi - span.height);
    span = cv::Rect(span.x - grow_x / 2, span.y - grow_y / 2, span.width + grow_x,
                    span.height + grow_y);
    r.region = span & frame;
  }
  const cv::Rect object = enclosing(box) & r.region;
  if (object.width < 2 || object.height < 2) return lose(LostReason::LeftRegion);

  // The pyramids of the part of frames t-1 and t this step reads. Frame t's part reaches ahead
  // by the velocity (and a few pixels), where the next step's part of it will most likely be.
  r.level = lk_level();
  levels = part_levels(r.level);
  const cv::Rect part = step_part(r.region, r.level);
  view_prev.levels.clear();  // the last step's views: let go so that builds reuse buffers
  view_cur.levels.clear();
  view_next.levels.clear();
  // The part of frame t-1 built by the last step serves when it covers this one with as many
  // levels (a part is on the grid of its coarsest level, so also on that of every finer one).
  if ((prev_part.rect & part) != part || prev_part.pyr.num_levels() < levels) {
    build(prev, prev_whole, part, prev_part);
  }
  cv::Rect ahead = part;
  if (!params.whole_frame) {
    const cv::Point shift(static_cast<int>(std::lround(velocity.x)),
                          static_cast<int>(std::lround(velocity.y)));
    ahead |= part + shift;
    ahead = aligned(grown(ahead, 4));
  }
  build(in.gray, in.pyramid, ahead, next_part);
  built = true;
  view(prev_part, part, levels, view_prev);
  view(next_part, part, levels, view_cur);
  view(next_part, next_part.rect, levels, view_next);
  const cv::Point origin = part.tl();

  flow::FlowOptions opt;
  opt.region = r.region - origin;
  opt.initial_motion = velocity;
  opt.context = params.lk_context;
  opt.finest_level = r.level;
  flow::dense_flow(view_prev, view_cur, params.lk, forward, opt, executor);
  r.region_flow = forward.flow.clone();

  // A regular grid over the object's pixels, in frame t-1, and where the flow takes them.
  const int step = std::max(1, static_cast<int>(std::ceil(std::sqrt(
                                   static_cast<double>(object.area()) / params.max_points))));
  from.clear();
  to.clear();
  conf.clear();
  work_x.clear();
  work_y.clear();
  const int off_x = (object.width - 1) % step / 2;
  const int off_y = (object.height - 1) % step / 2;
  for (int y = object.y + off_y; y < object.y + object.height; y += step) {
    const cv::Vec2f* fr = forward.flow.ptr<cv::Vec2f>(y - r.region.y);
    const float* cr = forward.confidence.ptr<float>(y - r.region.y);
    for (int x = object.x + off_x; x < object.x + object.width; x += step) {
      const cv::Vec2f f = fr[x - r.region.x];
      from.emplace_back(static_cast<float>(x), static_cast<float>(y));
      to.emplace_back(static_cast<float>(x) + f[0], static_cast<float>(y) + f[1]);
      conf.push_back(cr[x - r.region.x]);
      work_x.push_back(f[0]);
      work_y.push_back(f[1]);
    }
  }
  const cv::Point2f rough(median(work_x), median(work_y));
  r.texture = median(conf);

  // Backward LK around where the object went, seeded with the reverse of its rough motion.
  if (params.whole_frame) {
    opt.region = frame;
  } else {
    const int pad = 2 + static_cast<int>(std::ceil(params.fb_threshold));
    cv::Rect2f moved(static_cast<float>(object.x) + rough.x, static_cast<float>(object.y) + rough.y,
                     static_cast<float>(object.width), static_cast<float>(object.height));
    const cv::Rect b = enclosing(moved);
    opt.region = (grown(b, pad) & part) - origin;
  }
  opt.initial_motion = -rough;
  inliers.clear();
  if (!opt.region.empty()) {
    flow::LkParams back_lk = params.lk;
    back_lk.levels = std::min(params.lk.levels, params.fb_levels);
    flow::dense_flow(view_cur, view_prev, back_lk, backward, opt, executor);
    const cv::Point2f back_origin(static_cast<float>(backward.region.x + origin.x),
                                  static_cast<float>(backward.region.y + origin.y));
    const float limit2 = static_cast<float>(params.fb_threshold * params.fb_threshold);
    for (std::size_t i = 0; i < from.size(); ++i) {
      cv::Vec2f back;
      const cv::Point2f q = to[i] - back_origin;
      if (!sample(backward.flow, q.x, q.y, back)) continue;
      const float ex = to[i].x + back[0] - from[i].x;
      const float ey = to[i].y + back[1] - from[i].y;
      if (ex * ex + ey * ey <= limit2) inliers.push_back(static_cast<int>(i));
    }
  }
  r.inliers = static_cast<double>(inliers.size()) / static_cast<double>(from.size());
  LostReason flow_failure = LostReason::Found;
  if (inliers.size() < 3 || r.inliers < params.min_inliers) {
    flow_failure = LostReason::FewInliers;
  } else if (r.texture < params.min_texture) {
    flow_failure = LostReason::LowTexture;
  }

  cv::Point2f c = centre(predicted_box);
  double scale = 1.0;
  if (flow_failure == LostReason::Found) {
    const cv::Point2f motion = measure_motion(scale);
    c = centre(box) + motion;
  }

  // The first appearance never drifts, so it is preferred; a recent one takes over while the
  // object looks different (lighting, pose) and the first no longer matches well. Where the flow
  // failed (a sudden change of lighting breaks brightness constancy, an occlusion hides part of
  // the object) the appearance alone may still find it near the prediction, over a wider search.
  const cv::Rect2f flow_box = box_at(c, box.size() * static_cast<float>(scale));
  const double reach = flow_failure == LostReason::Found ? 1.0 : 2.0;
  // The appearance search and the recent appearance's cut read frame t's part beyond LK's (the
  // whole part built so far, grown where they need more).
  cv::Rect need = match_need(templ, flow_box, reach);
  if (!recent.empty()) need |= match_need(recent, flow_box, reach);
  cover(in, need);
  const cv::Point next_origin = next_part.rect.tl();
  Appearance a = match(templ, templ_sizes, view_next, next_origin, flow_box, reach);
  if (a.score < params.trust_appearance && !recent.empty()) {
    const Appearance b = match(recent, recent_sizes, view_next, next_origin, flow_box, reach);
    if (b.score > a.score) a = b;
  }
  r.appearance = a.score;
  // No score at all means no scale of the template fitted inside the frame (an object partly
  // out of view): that is no evidence against the flow's measurement.
  const bool matched = a.score > -1;
  if (flow_failure != LostReason::Found) {
    if (a.score < params.trust_appearance || a.at_edge) return lose(flow_failure);
    c = a.centre;
    scale = a.size_ratio;
  } else if (matched && a.score < params.min_appearance) {
    return lose(LostReason::Appearance);
  } else if (a.score >= params.trust_appearance && !a.at_edge) {
    const auto w = static_cast<float>(params.appearance_weight);
    c = (1.f - w) * c + w * a.centre;
    scale *= std::pow(a.size_ratio, params.appearance_weight);
  }
  if (!cv::Rect2f(r.region).contains(c)) return lose(LostReason::LeftRegion);
  // Between two frames a real object changes size by far less than this; a larger estimate is a
  // failed measurement, and a box must never collapse to nothing.
  scale = std::clamp(scale, 1.0 / kMaxScaleChange, kMaxScaleChange);
  if (std::min(box.width, box.height) * scale < 2.0) scale = 1.0;

  const cv::Point2f measured = c - centre(box);
  velocity += static_cast<float>(params.velocity_gain) * (measured - velocity);
  box = box_at(c, box.size() * static_cast<float>(scale));
  ++since_recent;
  if (flow_failure == LostReason::Found && a.score >= params.trust_appearance && r.inliers >= 0.5 &&
      since_recent >= params.template_interval) {
    cover(in, grown(enclosing(box), 2));
    cut(view_next, next_part.rect.tl(), box, recent);
    recent_sizes.clear();
    since_recent = 0;
  }
  advance();
  r.box = box;
  r.velocity = velocity;
  r.scale = scale;
  return r;
}

// Median flow of the inliers, and the median ratio of their pairwise distances (pairs closer
// than a fifth of the box would make noisy ratios) as `scale`.
cv::Point2f LocalTracker::Impl::measure_motion(double& scale) {
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

LocalTracker::LocalTracker(const LocalTrackerParams& params, const Executor* executor)
    : impl_(std::make_unique<Impl>()) {
  params.validate();
  impl_->params = params;
  impl_->executor = executor;
}

LocalTracker::~LocalTracker() = default;
LocalTracker::LocalTracker(LocalTracker&&) noexcept = default;
LocalTracker& LocalTracker::operator=(LocalTracker&&) noexcept = default;

const LocalTrackerParams& LocalTracker::params() const {
  return impl_->params;
}

void LocalTracker::start(const LocalFrame& frame, const cv::Rect2f& box) {
  Impl& s = *impl_;
  s.place(frame, box);
  // The appearance from the pyramid of the box and a margin wider than the smoothing: the
  // values there are the whole frame's.
  const cv::Rect b = enclosing(box);
  const cv::Rect around = s.aligned(grown(b, 8));
  s.build(frame.gray, frame.pyramid, around, s.prev_part);
  cut(s.prev_part.pyr, around.tl(), box, s.templ);
  s.templ_sizes.clear();
  s.recent.release();
  s.recent_sizes.clear();
  s.since_recent = 0;
}

void LocalTracker::restart(const LocalFrame& frame, const cv::Rect2f& box) {
  if (impl_->templ.empty()) throw Error("local tracker: restart() before start()");
  impl_->place(frame, box);
}

bool LocalTracker::started() const {
  return !impl_->prev.empty();
}

LocalResult LocalTracker::track(const LocalFrame& frame) {
  return impl_->track(frame);
}

cv::Rect2f LocalTracker::box() const {
  return impl_->box;
}

cv::Point2f LocalTracker::velocity() const {
  return impl_->velocity;
}

cv::Rect2f LocalTracker::predicted() const {
  const Impl& s = *impl_;
  return {s.box.x + s.velocity.x, s.box.y + s.velocity.y, s.box.width, s.box.height};
}

}  // namespace roiflow::stages
