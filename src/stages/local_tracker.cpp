#include "stages/local_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "core/error.hpp"
#include "core/text.hpp"
#include "stages/local_tracker_impl.hpp"

namespace roiflow::stages {
namespace {

void check_range(const char* name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    throw Error(std::string("local tracker: ") + name + " must be in [" + number_text(lo) + ", " +
                number_text(hi) + "], got " + number_text(value));
  }
}

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
