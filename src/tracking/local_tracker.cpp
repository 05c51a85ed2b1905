#include "tracking/local_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/local_tracker_impl.hpp"

namespace roiflow::tracking {
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
  if (!(foreground_tolerance > 0) || !std::isfinite(foreground_tolerance)) {
    throw Error("local tracker: foreground_tolerance must be > 0, got " +
                number_text(foreground_tolerance));
  }
  if (!(max_fb_error > 0) || !std::isfinite(max_fb_error)) {
    throw Error("local tracker: max_fb_error must be > 0, got " + number_text(max_fb_error));
  }
  if (!(max_frame_share > 0 && max_frame_share <= 1)) {
    throw Error("local tracker: max_frame_share must be in (0, 1], got " +
                number_text(max_frame_share));
  }
  if (!(moving_speed > 0) || !std::isfinite(moving_speed)) {
    throw Error("local tracker: moving_speed must be > 0, got " + number_text(moving_speed));
  }
  if (!(stop_share >= 0 && stop_share < 1)) {
    throw Error("local tracker: stop_share must be in [0, 1), got " + number_text(stop_share));
  }
  check_range("confident_appearance", confident_appearance, trust_appearance, 1);
  check_range("memory", memory, 0, 16);
  check_range("memory_interval", memory_interval, 1, 1e9);
  check_range("coast_decay", coast_decay, 0, 1);
  check_range("max_reach", max_reach, 2, 100);
  check_range("lost_prior", lost_prior, 0, 1);
  check_range("scale_check_interval", scale_check_interval, 0, 1000);
  if (!(scale_check_margin > 0 && scale_check_margin <= 1)) {
    throw Error("local tracker: scale_check_margin must be in (0, 1], got " +
                number_text(scale_check_margin));
  }
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
    case LostReason::FbError:
      return "fb-error";
    case LostReason::ScaleJump:
      return "scale-jump";
    case LostReason::TooLarge:
      return "too-large";
    case LostReason::Background:
      return "background";
    case LostReason::Searching:
      return "searching";
    case LostReason::Collapsed:
      return "collapsed";
    case LostReason::Still:
      return "still";
  }
  return "?";
}

void LocalTracker::Impl::advance(const LocalFrame& in) {
  // Frame t becomes frame t-1 of the next step, with the part of its pyramid built so far.
  prev = in.gray;
  prev_whole = params.whole_frame ? in.pyramid : nullptr;
  if (built) {
    std::swap(prev_part, next_part);
  } else {
    prev_part.rect = cv::Rect();
  }
  built = false;
}

LocalResult& LocalTracker::Impl::lose(LocalResult& r, LostReason why,
                                      const cv::Rect2f& predicted_box, const LocalFrame& in) {
  r.lost = true;
  r.reason = why;
  r.box = predicted_box;
  box = predicted_box;
  // Coasting: the prediction slows down while nothing confirms it.
  velocity *= static_cast<float>(params.coast_decay);
  r.velocity = velocity;
  lost = true;
  ++lost_frames;
  moving = 0;
  advance(in);
  return r;
}

// The region holds the object now and where it is predicted next, at least roi x roi, and
// (to measure the background's motion) a ring around them wider than an LK window.
cv::Rect LocalTracker::Impl::region_for(const cv::Rect2f& predicted_box, int lk_level) const {
  if (params.whole_frame) return frame_rect();
  cv::Rect span = enclosing(box) | enclosing(predicted_box);
  if (params.segment) span = grown(span, params.lk.patch * (1 << lk_level) + 2);
  const int grow_x = std::max(0, params.roi - span.width);
  const int grow_y = std::max(0, params.roi - span.height);
  span =
      cv::Rect(span.x - grow_x / 2, span.y - grow_y / 2, span.width + grow_x, span.height + grow_y);
  return span & frame_rect();
}

// The pyramids of the part of frames t-1 and t this step reads. Frame t's part reaches ahead by
// the velocity (and a few pixels), where the next step's part of it will most likely be.
cv::Point LocalTracker::Impl::build_step(const LocalFrame& in, const cv::Rect& region,
                                         int lk_level) {
  levels = part_levels(lk_level);
  const cv::Rect part = step_part(region, lk_level);
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
  return part.tl();
}

// A regular grid over the object's pixels, in frame t-1, and where the flow takes them; returns
// their median motion.
cv::Point2f LocalTracker::Impl::sample_object(const cv::Rect& object, const cv::Rect& region,
                                              double& texture) {
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
    const cv::Vec2f* fr = forward.flow.ptr<cv::Vec2f>(y - region.y);
    const float* cr = forward.confidence.ptr<float>(y - region.y);
    for (int x = object.x + off_x; x < object.x + object.width; x += step) {
      const cv::Vec2f f = fr[x - region.x];
      from.emplace_back(static_cast<float>(x), static_cast<float>(y));
      to.emplace_back(static_cast<float>(x) + f[0], static_cast<float>(y) + f[1]);
      conf.push_back(cr[x - region.x]);
      work_x.push_back(f[0]);
      work_y.push_back(f[1]);
    }
  }
  texture = median(conf);
  return {median(work_x), median(work_y)};
}

// Backward LK around where the object went, seeded with the reverse of its rough motion: fills
// `inliers` and returns the median forward-backward error (level-0 pixels; a pixel whose way
// back leaves the computed field counts as a large error).
double LocalTracker::Impl::backward_check(const cv::Rect& object, cv::Point2f rough,
                                          cv::Point origin, const cv::Rect& part, int lk_level) {
  flow::FlowOptions opt;
  opt.context = params.lk_context;
  opt.finest_level = lk_level;
  opt.confidence = false;  // only the way back is read (the flow is the same without it)
  if (params.whole_frame) {
    opt.region = frame_rect();
  } else {
    const int pad = 2 + static_cast<int>(std::ceil(params.fb_threshold));
    cv::Rect2f moved(static_cast<float>(object.x) + rough.x, static_cast<float>(object.y) + rough.y,
                     static_cast<float>(object.width), static_cast<float>(object.height));
    opt.region = (grown(enclosing(moved), pad) & part) - origin;
  }
  opt.initial_motion = -rough;
  inliers.clear();
  if (opt.region.empty()) return 1e9;
  backward_lk.calc(view_cur, view_prev, backward, opt);
  const cv::Point2f back_origin(static_cast<float>(backward.region.x + origin.x),
                                static_cast<float>(backward.region.y + origin.y));
  const float limit2 = static_cast<float>(params.fb_threshold * params.fb_threshold);
  conf.clear();
  for (std::size_t i = 0; i < from.size(); ++i) {
    cv::Vec2f back;
    const cv::Point2f q = to[i] - back_origin;
    if (!sample(backward.flow, q.x, q.y, back)) {
      conf.push_back(1e9f);
      continue;
    }
    const float ex = to[i].x + back[0] - from[i].x;
    const float ey = to[i].y + back[1] - from[i].y;
    conf.push_back(std::sqrt(ex * ex + ey * ey));
    if (ex * ex + ey * ey <= limit2) inliers.push_back(static_cast<int>(i));
  }
  return conf.empty() ? 1e9 : median(conf);
}

LocalResult LocalTracker::Impl::track(const LocalFrame& in) {
  if (prev.empty()) throw Error("local tracker: track() before start()");
  if (in.gray.size() != size) {
    throw Error("local tracker: frame is " + number_text(in.gray.cols) + " x " +
                number_text(in.gray.rows) + ", the previous one was " + number_text(size.width) +
                " x " + number_text(size.height));
  }
  check_frame(in);
  const cv::Rect2f predicted_box(box.x + velocity.x, box.y + velocity.y, box.width, box.height);
  const bool was_lost = lost;
  LocalResult r;
  r.velocity = velocity;
  built = false;
  r.level = lk_level();
  r.region = region_for(predicted_box, r.level);
  const cv::Rect object = enclosing(box) & r.region;
  if (object.width < 2 || object.height < 2)
    return lose(r, LostReason::LeftRegion, predicted_box, in);

  const cv::Point origin = build_step(in, r.region, r.level);
  const cv::Rect part(origin, view_prev.levels[0].size());
  flow::FlowOptions opt;
  opt.region = r.region - origin;
  opt.initial_motion = velocity;
  opt.context = params.lk_context;
  opt.finest_level = r.level;
  // The result shares the forward flow's buffer; it is written again only once nobody else
  // holds it (a sink may still hold the last one).
  if (forward.flow.u != nullptr && CV_XADD(&forward.flow.u->refcount, 0) > 1)
    forward.flow.release();
  forward_lk.calc(view_prev, view_cur, forward, opt);
  r.region_flow = forward.flow;
  const cv::Point2f rough = sample_object(object, r.region, r.texture);
  r.fb_error = backward_check(object, rough, origin, part, r.level);
  r.inliers = static_cast<double>(inliers.size()) / static_cast<double>(from.size());
  measure_background(r, box);

  cv::Point2f c = centre(predicted_box);
  double scale = 1.0;
  LostReason flow_failure = check_flow(r, 1.0);
  if (flow_failure == LostReason::Found) {
    const cv::Point2f motion = measure_motion(r, scale);
    c = centre(box) + motion;
    // A size change no object makes between two frames: the flow's scale failed (its position
    // may still hold); the appearance alone sizes the box.
    if (check_flow(r, scale) == LostReason::ScaleJump) scale = 1.0;
  }

  // The appearance (first look, recent, remembered) corrects the flow's box; where the flow
  // failed (a sudden change of lighting breaks brightness constancy, an occlusion hides part of
  // the object) or the target was lost, the appearance alone may find it, over a wider search.
  const bool by_look = flow_failure != LostReason::Found || was_lost;
  const cv::Rect2f flow_box = box_at(c, box.size() * static_cast<float>(scale));
  // While lost, the search widens frame after frame (the target may have moved on unseen).
  const double reach =
      !by_look ? 1.0 : std::min(params.max_reach, 2.0 + 0.5 * static_cast<double>(lost_frames));
  const Appearance a = look(in, flow_box, reach);
  r.appearance = a.score;
  // No score at all means no scale of the template fitted inside the frame (an object partly
  // out of view): that is no evidence against the flow's measurement.
  const bool matched = a.score > -1;
  if (by_look) {
    // Found again only by a look as good as a confident frame's: a wide search meets lookalikes.
    const double needed = was_lost ? params.confident_appearance : params.trust_appearance;
    if (a.score < needed || a.at_edge) {
      // Lost, but the flow holds: the box follows what the flow follows (the target, most often,
      // turned to a side none of its looks shows), still reported lost until a look confirms it.
      if (params.follow_lost && was_lost && flow_failure == LostReason::Found &&
          cv::Rect2f(r.region).contains(c)) {
        const cv::Point2f moved = c - centre(box);
        lose(r, LostReason::Searching, box_at(c, box.size()), in);
        velocity = moved;
        r.velocity = velocity;
        return r;
      }
      return lose(r, was_lost ? LostReason::Searching : flow_failure, predicted_box, in);
    }
    c = a.centre;
    scale = a.size_ratio;
    r.by_look_alone = flow_failure != LostReason::Found;
  } else if (matched && a.score < params.min_appearance) {
    return lose(r, LostReason::Appearance, predicted_box, in);
  } else if (a.score >= params.trust_appearance && !a.at_edge) {
    const auto w = static_cast<float>(params.appearance_weight);
    c = (1.f - w) * c + w * a.centre;
    scale *= std::pow(a.size_ratio, params.appearance_weight);
  }
  if (!cv::Rect2f(r.region).contains(c)) return lose(r, LostReason::LeftRegion, predicted_box, in);
  // A box must never collapse to nothing.
  scale = std::clamp(scale, 1.0 / kMaxScaleChange, kMaxScaleChange);
  if (std::min(box.width, box.height) * scale < 2.0) scale = 1.0;
  cv::Rect2f next = box_at(c, box.size() * static_cast<float>(scale));
  // Held by the flow: now and then, the first look checks the size over a wide range.
  if (!by_look && check_size(in, next)) {
    scale = static_cast<double>(next.width) / static_cast<double>(box.width);
    c = centre(next);
  }
  const cv::Point2f measured = c - centre(box);
  const LostReason state = check_state(r, measured, next);
  if (state != LostReason::Found) return lose(r, state, predicted_box, in);

  learn_motion(r, measured);
  lost = false;
  lost_frames = 0;
  velocity += static_cast<float>(params.velocity_gain) * (measured - velocity);
  box = next;
  if (flow_failure == LostReason::Found) remember(in, a.score, r.inliers);
  advance(in);
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
  impl_->forward_lk = flow::DenseLK(params.lk, executor);
  flow::LkParams back_lk = params.lk;
  back_lk.levels = std::min(params.lk.levels, params.fb_levels);
  impl_->backward_lk = flow::DenseLK(back_lk, executor);
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
  s.memory.clear();
  s.memory_sizes.clear();
  s.since_memory = 0;
  s.wide_sizes.clear();
}

void LocalTracker::restart(const LocalFrame& frame, const cv::Rect2f& box) {
  if (impl_->templ.empty()) throw Error("local tracker: restart() before start()");
  impl_->place(frame, box);
}

void LocalTracker::restart(const LocalFrame& frame, const cv::Rect2f& box, cv::Point2f velocity) {
  if (!(std::isfinite(velocity.x) && std::isfinite(velocity.y))) {
    throw Error("local tracker: restart() velocity must be finite");
  }
  restart(frame, box);
  impl_->velocity = velocity;
}

double LocalTracker::verify(const LocalFrame& frame, const cv::Rect2f& box) {
  if (impl_->prev.empty()) throw Error("local tracker: verify() before start()");
  return impl_->verify(frame, box);
}

bool LocalTracker::lost() const {
  return impl_->lost;
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

}  // namespace roiflow::tracking
