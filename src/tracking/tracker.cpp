#include "tracking/tracker.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>
#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/camera_motion.hpp"
#include "tracking/select_impl.hpp"

namespace roiflow::tracking {
namespace {

std::string spaced_size_text(cv::Size s) {
  return number_text(s.width) + " x " + number_text(s.height);
}

std::string box_text(const cv::Rect2f& b) {
  return "(" + number_text(b.x) + ", " + number_text(b.y) + ", " + number_text(b.width) + " x " +
         number_text(b.height) + ")";
}

cv::Point2f centre(const cv::Rect2f& r) {
  return {r.x + 0.5f * r.width, r.y + 0.5f * r.height};
}

cv::Rect2f box_at(cv::Point2f c, cv::Size2f s) {
  return {c.x - 0.5f * s.width, c.y - 0.5f * s.height, s.width, s.height};
}

// How many pixels of two 8-bit images of one size differ by more than `level` grey levels (as
// countNonZero(absdiff(a, b) > level), without the two images it makes).
double changed_pixels(const cv::Mat& a, const cv::Mat& b, double level) {
  // For whole grey levels d, d > level exactly when d > floor(level).
  const int above = static_cast<int>(std::floor(level));
  long long n = 0;
  for (int y = 0; y < a.rows; ++y) {
    const std::uint8_t* pa = a.ptr<std::uint8_t>(y);
    const std::uint8_t* pb = b.ptr<std::uint8_t>(y);
    int row = 0;
    for (int x = 0; x < a.cols; ++x)
      row += std::abs(static_cast<int>(pa[x]) - static_cast<int>(pb[x])) > above;
    n += row;
  }
  return static_cast<double>(n);
}

// Median flow magnitude over a grid of the region's pixels that lie outside the object's box:
// how fast the background moves, or -1 when the region holds too little of it to tell.
double background_motion(const cv::Mat& flow, const cv::Rect& region, const cv::Rect2f& box) {
  if (flow.empty()) return -1;
  const int step = std::max(1, static_cast<int>(std::sqrt(region.area() / 256.0)));
  std::vector<float> speeds;
  for (int y = 0; y < region.height; y += step) {
    const cv::Vec2f* row = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < region.width; x += step) {
      if (box.contains(cv::Point2f(static_cast<float>(region.x + x) + 0.5f,
                                   static_cast<float>(region.y + y) + 0.5f))) {
        continue;
      }
      speeds.push_back(std::hypot(row[x][0], row[x][1]));
    }
  }
  if (speeds.size() < 16) return -1;
  return detail::kth_smallest(speeds.data(), speeds.size(), speeds.size() / 2);
}

// A moving object found by background subtraction arrives with its recent past: the blob holds
// the object and the "ghost" it left where the model had not yet learned the background (and
// its motion blur). The paper's global treatment measures motion; so does this: LK over the
// blob and its surroundings between the previous and this frame, the largest set of pixels that
// really move, their box moved by their median flow. The motion boundary that LK's window
// spreads by about half a window is taken off each side. Returns `box` unchanged when too few
// pixels move.
cv::Rect2f refine_by_motion(const flow::Pyramid& previous, const flow::Pyramid& current,
                            const flow::LkParams& lk, const cv::Rect2f& box,
                            const Executor* executor) {
  const cv::Size size = current.size();
  const float pad = 0.1f * std::max(box.width, box.height) + 8.f;
  const cv::Rect region = cv::Rect(cv::Point(static_cast<int>(std::floor(box.x - pad)),
                                             static_cast<int>(std::floor(box.y - pad))),
                                   cv::Point(static_cast<int>(std::ceil(box.br().x + pad)),
                                             static_cast<int>(std::ceil(box.br().y + pad)))) &
                          cv::Rect(cv::Point(), size);
  if (region.width < 8 || region.height < 8) return box;
  flow::FlowOptions options;
  options.region = region;
  const flow::FlowResult r = flow::dense_flow(previous, current, lk, options, executor);
  std::vector<cv::Mat> uv;
  cv::split(r.flow, uv);
  cv::Mat magnitude;
  cv::magnitude(uv[0], uv[1], magnitude);
  std::vector<float> values(magnitude.begin<float>(), magnitude.end<float>());
  const auto p90 = values.begin() + static_cast<std::ptrdiff_t>(values.size() * 9 / 10);
  std::nth_element(values.begin(), p90, values.end());
  const float threshold = std::max(0.5f, 0.7f * *p90);
  cv::Mat moving = magnitude > threshold;
  cv::morphologyEx(moving, moving, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(moving, labels, stats, centroids, 8, CV_32S);
  int best = 0;
  for (int i = 1; i < n; ++i) {
    if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) {
      best = i;
    }
  }
  if (best == 0 || stats.at<int>(best, cv::CC_STAT_AREA) < 16) return box;
  std::vector<float> us, vs;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (labels.at<int>(y, x) != best) continue;
      const cv::Vec2f f = r.flow.at<cv::Vec2f>(y, x);
      us.push_back(f[0]);
      vs.push_back(f[1]);
    }
  }
  const float du = detail::median(us), dv = detail::median(vs);
  const float spread = 0.5f * static_cast<float>(lk.patch) - 1.f;
  const float w = static_cast<float>(stats.at<int>(best, cv::CC_STAT_WIDTH)) - 2.f * spread;
  const float h = static_cast<float>(stats.at<int>(best, cv::CC_STAT_HEIGHT)) - 2.f * spread;
  if (w < 4.f || h < 4.f) return box;
  const cv::Rect2f moved(
      static_cast<float>(region.x + stats.at<int>(best, cv::CC_STAT_LEFT)) + spread + du,
      static_cast<float>(region.y + stats.at<int>(best, cv::CC_STAT_TOP)) + spread + dv, w, h);
  // The blob's edges are exact where the object leads (no ghost there) and LK's where it
  // trails: their intersection keeps the better of both.
  const cv::Rect2f both = moved & box;
  return both.width >= 4.f && both.height >= 4.f ? both : moved;
}

// Where `box`'s pixels in `previous` went in `current`: the best normalised cross-correlation of
// them within one box side (the longer) each way. The box moved there, or nothing when too
// little of it lies inside the frame.
std::optional<cv::Rect2f> follow_look(const cv::Mat& previous, const cv::Mat& current,
                                      const cv::Rect2f& box) {
  const cv::Rect frame(cv::Point(), current.size());
  const cv::Rect patch =
      cv::Rect(cv::Point(static_cast<int>(std::round(box.x)), static_cast<int>(std::round(box.y))),
               cv::Size(static_cast<int>(std::round(box.width)),
                        static_cast<int>(std::round(box.height)))) &
      frame;
  if (patch.width < 4 || patch.height < 4) return std::nullopt;
  const int reach = std::max(patch.width, patch.height);
  const cv::Rect window = cv::Rect(patch.x - reach, patch.y - reach, patch.width + 2 * reach,
                                   patch.height + 2 * reach) &
                          frame;
  if (window.width < patch.width || window.height < patch.height) return std::nullopt;
  cv::Mat score;
  cv::matchTemplate(current(window), previous(patch), score, cv::TM_CCOEFF_NORMED);
  cv::Point best;
  cv::minMaxLoc(score, nullptr, nullptr, nullptr, &best);
  const cv::Point2f shift(static_cast<float>(window.x + best.x - patch.x),
                          static_cast<float>(window.y + best.y - patch.y));
  return cv::Rect2f(box.tl() + shift, box.size());
}

}  // namespace

void TrackerParams::validate() const {
  if (roi < 8 || roi > 4096)
    throw Error("tracker: roi must be in 8..4096, got " + number_text(roi));
  lk.validate();
  if (init) {
    const cv::Rect2f& b = *init;
    // Bounded so that the box's corners convert to int pixel coordinates without overflow.
    constexpr float kFar = 1e6f;
    if (!(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.width) &&
          std::isfinite(b.height) && b.width >= 2 && b.height >= 2 && std::abs(b.x) <= kFar &&
          std::abs(b.y) <= kFar && b.width <= kFar && b.height <= kFar)) {
      throw Error("tracker: init box " + box_text(b) +
                  " must be finite, within 1e6 pixels of the origin, with sides of 2..1e6 pixels");
    }
  }
  local.validate();
  if (!(camera_motion > 0) || !std::isfinite(camera_motion)) {
    throw Error("tracker: camera_motion must be > 0, got " + number_text(camera_motion));
  }
  if (observe_interval < 1 || observe_interval > 1000) {
    throw Error("tracker: observe_interval must be in 1..1000, got " +
                std::to_string(observe_interval));
  }
  if (!(verify >= -1 && verify <= 1)) {
    throw Error("tracker: verify must be in [-1, 1], got " + number_text(verify));
  }
  if (!(reach_growth >= 0 && reach_growth <= 10)) {
    throw Error("tracker: reach_growth must be in [0, 10], got " + number_text(reach_growth));
  }
  if (redetect_interval < 1 || redetect_interval > 1000) {
    throw Error("tracker: redetect_interval must be in 1..1000, got " +
                std::to_string(redetect_interval));
  }
  if (!(colour_verify >= -1 && colour_verify <= 1)) {
    throw Error("tracker: colour_verify must be in [-1, 1], got " + number_text(colour_verify));
  }
  if (colour_interval < 1 || colour_interval > 1000) {
    throw Error("tracker: colour_interval must be in 1..1000, got " +
                std::to_string(colour_interval));
  }
  if (confirm_frames < 1 || confirm_frames > 100) {
    throw Error("tracker: confirm_frames must be in 1..100, got " + std::to_string(confirm_frames));
  }
  if (!(confirm_verify >= -1 && confirm_verify <= 1)) {
    throw Error("tracker: confirm_verify must be in [-1, 1], got " + number_text(confirm_verify));
  }
  if (!(verify_far >= verify && verify_far <= 1)) {
    throw Error("tracker: verify_far must be in [verify, 1], got " + number_text(verify_far));
  }
  if (!(held_learning > 0 && held_learning <= 1)) {
    throw Error("tracker: held_learning must be in (0, 1], got " + number_text(held_learning));
  }
  if (!(min_side >= 0 && min_side <= 1000)) {
    throw Error("tracker: min_side must be in [0, 1000], got " + number_text(min_side));
  }
  if (still_frames < 0 || still_frames > 100000) {
    throw Error("tracker: still_frames must be in 0..100000, got " + std::to_string(still_frames));
  }
  if (!(still_level >= 0 && still_level <= 255) || !(still_share >= 0 && still_share <= 1)) {
    throw Error("tracker: still_level must be in [0, 255] and still_share in [0, 1], got " +
                number_text(still_level) + " and " + number_text(still_share));
  }
  detector.validate();
}

TrackRecord TrackerOutput::record() const {
  TrackRecord r;
  r.frame = index + 1;
  r.box = box;
  r.velocity = velocity;
  r.mode = mode;
  r.lost = lost || !has_target;  // no target yet: nothing was found on this frame
  r.ms = ms;
  return r;
}

// self_check compares a box with the frame this many frames back: a slow object changes its
// pixels more over a few frames than between two.
constexpr std::size_t kStillBaseline = 4;

struct Tracker::Impl {
  TrackerParams params;
  LocalTracker local;
  GlobalDetector detector;
  cv::Size size;  // of the first frame; empty before it
  bool has_target = false;
  bool lost = false;
  bool camera_moves = false;
  cv::Point2f rel_velocity;   // the target's recent motion relative to the background
  cv::Rect2f last_held;       // the target's box the last time the local treatment held it
  long long frames_lost = 0;  // frames lost in a row
  long long still_run = 0;    // frames in a row the held box held no moving pixels
  float start_side = 0;       // the shorter side of the box the target was started from
  long long activations = 0;
  long long observed_index = -1;  // the last frame given to the background model
  // The provisional re-detection (confirm_frames): its box on the last lost frame and on how many
  // consecutive lost frames it held (0 = none).
  cv::Rect2f candidate;
  int candidate_frames = 0;
  long long candidate_seen = 0;  // the last frame it held on

  static LocalTrackerParams local_params(const TrackerParams& p) {
    p.validate();
    LocalTrackerParams l = p.local;
    l.roi = p.roi;
    l.lk = p.lk;
    l.whole_frame = p.mode == TrackMode::Global;
    return l;
  }

  Impl(const TrackerParams& p, const Executor* executor_)
      : params(p), local(local_params(p), executor_), detector(p.detector), executor(executor_) {}

  const Executor* executor;
  // The last frame's gray image, and its whole pyramid while the target is being acquired
  // (refine_by_motion needs both frames' whole pyramids; the local treatment builds its own).
  cv::Mat previous_gray;
  std::deque<cv::Mat> recent_gray;  // the last frames' gray images, newest last (self_check)
  std::shared_ptr<const flow::Pyramid> previous;
  std::atomic<bool> wants_pyramid{true};
  // The background refresh running beside the frames while the target is held (it touches
  // the detector's background model only; set_target_size, the one detector call a held frame
  // makes, touches the target's size). Waited for before the model is used again. Declared
  // last: destroyed (so waited for) before everything it touches.
  std::unique_ptr<Job> refresh;

  // Waits for the background refresh; rethrows what it threw.
  void finish_refresh() {
    if (refresh) std::exchange(refresh, nullptr)->wait();
  }

  // The frame's whole pyramid: the one that came with it, else built now.
  std::shared_ptr<const flow::Pyramid> whole_pyramid(
      const cv::Mat& gray, std::shared_ptr<const flow::Pyramid> given) const {
    if (given) return given;
    return std::make_shared<const flow::Pyramid>(
        flow::build_pyramid(gray, params.lk.levels, params.lk.sigma));
  }

  TrackerOutput process(const TrackerInput& frame);
  void acquire(const TrackerInput& frame, TrackerOutput& out);
  void follow(const TrackerInput& frame, TrackerOutput& out, double refresh_weight);
  LostReason self_check(const TrackerInput& frame, const cv::Rect2f& box);
  bool confirm_candidate(const TrackerInput& frame, const cv::Mat& image, TrackerOutput& out);
  bool held_by_local(const TrackerInput& frame, const LocalResult& r);
  void retry_by_camera(const TrackerInput& frame, const cv::Rect2f& before,
                       cv::Point2f velocity_before, LocalResult& r);

  // The background model is only needed to find a target that was not given. `weight`: the
  // frames of video this observation stands for. `beside`: as a job of the executor, beside the
  // frames that follow (a refresh while the target is held is not needed before it is lost);
  // at once without an executor.
  void observe(const TrackerInput& frame, double weight = 1.0, bool beside = false) {
    finish_refresh();
    if (params.init || observed_index == frame.index) return;
    if (beside && executor != nullptr) {
      // The job keeps the frame alive, and makes a deferred picture on its own thread.
      GlobalDetector* model = &detector;
      const TrackerInput in{frame.index, frame.image, frame.gray, nullptr, frame.deferred_image};
      refresh = executor->start([model, in, weight] { model->observe(in.picture(), weight); });
    } else {
      detector.observe(frame.picture(), weight);
    }
    observed_index = frame.index;
  }
};

void Tracker::Impl::acquire(const TrackerInput& frame, TrackerOutput& out) {
  finish_refresh();
  const cv::Mat image = frame.picture();
  if (params.init) {
    const cv::Rect2f& b = *params.init;
    const cv::Rect2f inside =
        b & cv::Rect2f(0.f, 0.f, static_cast<float>(size.width), static_cast<float>(size.height));
    if (inside.width < 2 || inside.height < 2) {
      throw Error("tracker: init box " + box_text(b) + " lies outside the " +
                  spaced_size_text(size) + " frame");
    }
    detector.set_target(image, b);
    local.start({frame.gray, frame.pyramid}, b);
    last_held = b;
    start_side = std::min(inside.width, inside.height);
    if (params.mode == TrackMode::Global) ++activations;
    out.mode =
        params.mode == TrackMode::Global ? TrackRecord::Mode::Global : TrackRecord::Mode::Local;
    out.box = b;
  } else {
    // Without a given target the global treatment runs on every frame until it finds one.
    ++activations;
    const std::vector<Detection> objects = detector.moving_objects();
    out.mode = TrackRecord::Mode::Global;
    if (objects.empty()) return;
    cv::Rect2f box = objects.front().box;
    if (!previous_gray.empty()) {
      previous = whole_pyramid(previous_gray, previous);
      box = refine_by_motion(*previous, *whole_pyramid(frame.gray, frame.pyramid), params.lk, box,
                             executor);
    }
    detector.set_target(image, box);
    local.start({frame.gray, frame.pyramid}, box);
    last_held = box;
    start_side = std::min(box.width, box.height);
    out.box = box;
  }
  has_target = true;
  out.has_target = true;
}

// Why a box the local treatment holds is no tracked object (Found: it is one): too little of
// it lies in the frame, or (a target found by its motion) it held no moving pixels for
// still_frames frames.
LostReason Tracker::Impl::self_check(const TrackerInput& frame, const cv::Rect2f& box) {
  const cv::Rect2f frame_box(0.f, 0.f, static_cast<float>(size.width),
                             static_cast<float>(size.height));
  const cv::Rect2f inside = box & frame_box;
  // A target started smaller than twice min_side collapses at half its start size.
  const float min_side = std::min(static_cast<float>(params.min_side), start_side / 2);
  if (inside.width < min_side || inside.height < min_side) return LostReason::Collapsed;
  if (params.init || params.still_frames == 0 || recent_gray.empty() || camera_moves) {
    still_run = 0;
    return LostReason::Found;
  }
  const cv::Rect r = cv::Rect(inside) & cv::Rect(cv::Point(), size);
  if (r.empty()) return LostReason::Collapsed;
  // Against the frame still_baseline frames back (the oldest kept when fewer have been seen).
  const std::size_t back = std::min(recent_gray.size(), static_cast<std::size_t>(kStillBaseline));
  const double moving =
      changed_pixels(frame.gray(r), recent_gray[recent_gray.size() - back](r), params.still_level);
  still_run = moving <= params.still_share * r.area() ? still_run + 1 : 0;
  return still_run >= params.still_frames ? LostReason::Still : LostReason::Found;
}

// check_recovery: whether a box the local treatment holds is the target's. A box placed by a
// weak look alone (the flow failed) is not; after a loss, one the local treatment holds again is
// once its colours match the target's (as a re-detection's must).
bool Tracker::Impl::held_by_local(const TrackerInput& frame, const LocalResult& r) {
  if (!lost) return !r.by_look_alone || r.appearance >= params.local.confident_appearance;
  return params.colour_verify <= -1 ||
         detector.colour_similarity(frame.picture(), r.box) >= params.colour_verify;
}

// A provisional re-detection (confirm_frames) is followed by its own look and checked again;
// true when that confirms it (the target is placed there, `out` says so).
bool Tracker::Impl::confirm_candidate(const TrackerInput& frame, const cv::Mat& image,
                                      TrackerOutput& out) {
  if (candidate_frames > 0 && candidate_seen == frame.index - 1) {
    const std::optional<cv::Rect2f> moved = follow_look(previous_gray, frame.gray, candidate);
    const bool holds = moved &&
                       local.verify({frame.gray, frame.pyramid}, *moved) >= params.confirm_verify &&
                       (params.colour_verify <= -1 ||
                        detector.colour_similarity(image, *moved) >= params.colour_verify);
    candidate_frames = holds ? candidate_frames + 1 : 0;
    if (holds) {
      candidate = *moved;
      candidate_seen = frame.index;
    }
    const cv::Rect2f placed = box_at(centre(candidate), last_held.size());
    if (holds && candidate_frames >= params.confirm_frames &&
        self_check(frame, placed) == LostReason::Found) {
      candidate_frames = 0;
      local.restart({frame.gray, frame.pyramid}, placed);
      out.reason = LostReason::Found;
      lost = false;
      out.box = placed;
      return true;
    }
  } else {
    candidate_frames = 0;
  }
  return false;
}

// A camera that jumps takes the target further than its velocity predicts: the step that lost a
// held target runs once more from the frame before, predicted where the picture's own shift and
// the target's motion relative to the background take it, and replaces `r` when it holds. A
// prediction within half the box's shorter side of the first is within the first step's reach.
void Tracker::Impl::retry_by_camera(const TrackerInput& frame, const cv::Rect2f& before,
                                    cv::Point2f velocity_before, LocalResult& r) {
  if (previous_gray.empty()) return;
  const std::optional<cv::Point2f> g = camera_shift(previous_gray, frame.gray, before);
  if (!g) return;
  const cv::Point2f v = *g + rel_velocity;
  const cv::Point2f change = v - velocity_before;
  const float side = 0.5f * std::min(before.width, before.height);
  if (change.dot(change) <= std::max(4.f, side * side)) return;
  local.restart({previous_gray, nullptr}, before, v);
  LocalResult again = local.track({frame.gray, frame.pyramid});
  if (!again.lost) {
    r = std::move(again);
    return;
  }
  // Not there either: the first measurement stands (the same step again, from the same state).
  local.restart({previous_gray, nullptr}, before, velocity_before);
  r = local.track({frame.gray, frame.pyramid});
}

void Tracker::Impl::follow(const TrackerInput& frame, TrackerOutput& out, double refresh_weight) {
  const cv::Rect2f before = local.box();  // where the object was on the grid of region_flow
  const cv::Point2f velocity_before = local.velocity();
  if (refresh_weight > 0) observe(frame, refresh_weight, true);
  LocalResult r = local.track({frame.gray, frame.pyramid});
  if (r.lost && !lost && params.camera_retry) retry_by_camera(frame, before, velocity_before, r);
  if (!r.lost && r.background_known) {
    rel_velocity = 0.5f * rel_velocity + 0.5f * (centre(r.box) - centre(before) - r.background);
  }
  out.has_target = true;
  out.region = r.region;
  out.region_flow = r.region_flow;
  const bool global_mode = params.mode == TrackMode::Global;
  if (global_mode) ++activations;
  out.mode = global_mode ? TrackRecord::Mode::Global : TrackRecord::Mode::Local;
  if (!r.region_flow.empty()) {
    const double bg = background_motion(r.region_flow, r.region, before);
    if (bg >= 0) camera_moves = bg > params.camera_motion;
  }
  out.reason = r.reason;
  LostReason self = r.lost ? r.reason : self_check(frame, r.box);
  if (self == LostReason::Found && params.check_recovery && !held_by_local(frame, r)) {
    self = LostReason::Searching;
  }
  if (self != r.reason) out.reason = self;
  if (self == LostReason::Found) {
    lost = false;
    frames_lost = 0;
    candidate_frames = 0;
    last_held = r.box;
    out.box = r.box;
    out.velocity = r.velocity;
    // Only a confident frame tells the re-detection the target's size: a drifting box would
    // have it search at the drift's scale.
    if (r.appearance >= params.local.trust_appearance) detector.set_target_size(r.box.size());
    // The colour memory follows the target (lighting, pose) from confident frames only.
    if (params.colour_verify > -1 && r.appearance >= params.local.confident_appearance &&
        frame.index % params.colour_interval == 0) {
      detector.remember_colour(frame.picture(), r.box);
    }
    return;
  }
  // Lost: the global treatment searches the whole frame; until it succeeds the box coasts.
  finish_refresh();
  if (!global_mode) ++activations;
  out.mode = TrackRecord::Mode::Global;
  const cv::Mat image = frame.picture();
  observe(frame);
  const bool by_appearance = params.init.has_value() || camera_moves;
  // The whole-frame search costs tens of local steps on a large frame: while the target stays
  // lost it runs on the first lost frame and then every redetect_interval frames (the local
  // treatment searches around the coasting box every frame).
  if (confirm_candidate(frame, image, out)) return;
  const bool search = (frames_lost % params.redetect_interval == 0);
  const std::optional<Detection> found =
      search ? detector.find_target(image, frame.gray, centre(r.box), by_appearance) : std::nullopt;
  // A re-detection is verified against every look the local treatment keeps (first, recent,
  // remembered) at a finer level before the target is placed there again.
  const double ver = found && found->box.width >= 2 && found->box.height >= 2
                         ? local.verify({frame.gray, frame.pyramid}, found->box)
                         : -2;
  // Objects do not jump: a re-detection far from where the target was last held is taken only
  // when its look is unmistakable; near it (a distance that grows while the target stays lost)
  // a good one suffices.
  const cv::Rect2f frame_box(0.f, 0.f, static_cast<float>(size.width),
                             static_cast<float>(size.height));
  const cv::Rect2f seen = found ? found->box & frame_box : cv::Rect2f();
  bool accept = found && seen.width >= 4 && seen.height >= 4 && ver >= params.verify;
  if (accept && ver < params.verify_far) {
    const cv::Point2f d = centre(found->box) - centre(last_held);
    const float reach =
        std::max(last_held.width, last_held.height) *
        (1.5f + static_cast<float>(params.reach_growth) * static_cast<float>(frames_lost));
    accept = d.dot(d) <= reach * reach;
  }
  // Gray NCC alone takes another object of the same shape: the colours must match one of the
  // target's colour looks too.
  if (accept && params.colour_verify > -1 &&
      detector.colour_similarity(image, found->box) < params.colour_verify) {
    accept = false;
  }
  // Short of unmistakable, a re-detection is held provisionally: it is followed by its own look
  // from frame to frame and taken once it has matched the target's looks and colours on
  // confirm_frames consecutive frames (a lookalike the search returns for one frame does not
  // capture the track).
  if (accept && ver < params.verify_far && params.confirm_frames > 1) {
    accept = false;
    if (candidate_frames == 0) {
      candidate = found->box;
      candidate_frames = 1;
      candidate_seen = frame.index;
    }
  }
  // At the size the target was last held at: a whole-frame NCC search favours the smaller of
  // its coarse scales (a part of the object matches as well as the whole), and re-detection
  // after re-detection would shrink the box; the local treatment measures the size again.
  const cv::Rect2f placed = accept ? box_at(centre(found->box), last_held.size()) : cv::Rect2f();
  // A re-detection is held to the same self-checks as a held box.
  const LostReason again = accept ? self_check(frame, placed) : LostReason::Found;
  if (again != LostReason::Found) out.reason = again;
  if (accept && again == LostReason::Found) {
    candidate_frames = 0;
    local.restart({frame.gray, frame.pyramid}, placed);
    out.reason = LostReason::Found;
    lost = false;
    out.box = placed;
    return;
  }
  lost = true;
  ++frames_lost;
  out.lost = true;
  out.box = r.box;
  // The box goes where the provisional re-detection is; the target stays lost until it is
  // confirmed.
  if (candidate_frames > 0) out.box = box_at(centre(candidate), last_held.size());
  out.velocity = r.velocity;
}

TrackerOutput Tracker::Impl::process(const TrackerInput& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  if (frame.gray.empty() || frame.gray.type() != CV_8UC1) {
    throw Error(
        "tracker: frame " + number_text(static_cast<double>(frame.index)) +
        ": gray must be 8-bit single-channel, got " +
        (frame.gray.empty() ? std::string("an empty image") : cv::typeToString(frame.gray.type())));
  }
  if (size.empty()) size = frame.gray.size();
  if (frame.gray.size() != size) {
    throw Error("tracker: frame " + number_text(static_cast<double>(frame.index)) + " is " +
                spaced_size_text(frame.gray.size()) + ", the first frame was " +
                spaced_size_text(size));
  }
  if (!frame.image.empty() && frame.image.size() != size) {
    throw Error("tracker: frame " + number_text(static_cast<double>(frame.index)) + ": image is " +
                spaced_size_text(frame.image.size()) + " but gray is " + spaced_size_text(size));
  }
  if (frame.pyramid &&
      (frame.pyramid->size() != size ||
       frame.pyramid->num_levels() < flow::effective_levels(size, params.lk.levels))) {
    throw Error("tracker: frame " + number_text(static_cast<double>(frame.index)) +
                ": the pyramid must be built from gray with pyramid_levels() levels");
  }
  // While the target is held, the background model is refreshed beside the frames.
  double refresh_weight = 0;
  if (!has_target || lost) {
    observe(frame);
  } else if (frame.index % params.observe_interval == 0 && !params.init) {
    refresh_weight = params.observe_interval * params.held_learning;
  }

  TrackerOutput out;
  out.index = frame.index;
  if (has_target) {
    follow(frame, out, refresh_weight);
  } else {
    acquire(frame, out);
  }
  previous_gray = frame.gray;
  recent_gray.push_back(frame.gray);
  if (recent_gray.size() > kStillBaseline) recent_gray.pop_front();
  previous = has_target ? nullptr : frame.pyramid;
  wants_pyramid.store(params.mode == TrackMode::Global || !has_target, std::memory_order_relaxed);
  out.global_activations = activations;
  out.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

Tracker::Tracker(const TrackerParams& params, const Executor* executor)
    : impl_(std::make_unique<Impl>(params, executor)) {}

Tracker::~Tracker() = default;
Tracker::Tracker(Tracker&&) noexcept = default;
Tracker& Tracker::operator=(Tracker&&) noexcept = default;

int Tracker::pyramid_levels() const {
  return impl_->params.lk.levels;
}

double Tracker::pyramid_sigma() const {
  return impl_->params.lk.sigma;
}

TrackerOutput Tracker::process(const TrackerInput& frame) {
  return impl_->process(frame);
}

long long Tracker::global_activations() const {
  return impl_->activations;
}

bool Tracker::wants_pyramid() const {
  return impl_->wants_pyramid.load(std::memory_order_relaxed);
}

void Tracker::finish_background_work() {
  impl_->finish_refresh();
}

const char* to_string(TrackMode mode) {
  return mode == TrackMode::Global ? "global" : "local";
}

TrackMode track_mode_from_string(std::string_view name) {
  if (name == "local") return TrackMode::Local;
  if (name == "global") return TrackMode::Global;
  throw Error("unknown track mode '" + std::string(name) + "' (expected local or global)");
}

}  // namespace roiflow::tracking
