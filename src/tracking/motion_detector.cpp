#include "tracking/motion_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/background_segm.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/banded_mog2.hpp"
#include "tracking/shadow_parts.hpp"
#include "tracking/start_motion_impl.hpp"

namespace roiflow::tracking {

void MotionDetectorParams::validate() const {
  auto fail = [](const std::string& what) { throw Error("motion detector: " + what); };
  if (history < 2) fail("history must be >= 2, got " + number_text(history));
  if (!(var_threshold > 0) || !std::isfinite(var_threshold))
    fail("var_threshold must be > 0, got " + number_text(var_threshold));
  if (work_width < 0 || work_width > 1 << 16)
    fail("work_width must be in 0..65536, got " + number_text(work_width));
  if (warmup < 0) fail("warmup must be >= 0, got " + number_text(warmup));
  if (open < 0 || open > 64) fail("open must be in 0..64, got " + number_text(open));
  if (close < 0 || close > 64) fail("close must be in 0..64, got " + number_text(close));
  if (!(min_area >= 1) || !std::isfinite(min_area))
    fail("min_area must be >= 1, got " + number_text(min_area));
  if (!(min_model_area >= 0) || !std::isfinite(min_model_area))
    fail("min_model_area must be >= 0, got " + number_text(min_model_area));
  if (!(split_valley >= 0 && split_valley < 1))
    fail("split_valley must be in [0, 1), got " + number_text(split_valley));
  if (!(split_width > 0 && split_width < 4))
    fail("split_width must be in (0, 4), got " + number_text(split_width));
  if (close_h < 0 || close_h > 64) fail("close_h must be in 0..64, got " + number_text(close_h));
  if (!(shadow_enclosed >= 0 && shadow_enclosed <= 1))
    fail("shadow_enclosed must be in [0, 1], got " + number_text(shadow_enclosed));
  if (!(join_gap >= 0 && join_gap <= 2))
    fail("join_gap must be in [0, 2], got " + number_text(join_gap));
  if (ghost_frames < 0 || ghost_frames > 100000)
    fail("ghost_frames must be in 0..100000, got " + number_text(ghost_frames));
  if (start_frames < 0 || start_frames > 100000)
    fail("start_frames must be in 0..100000, got " + number_text(start_frames));
  if (change_frames < 1 || change_frames > 1000)
    fail("change_frames must be in 1..1000, got " + number_text(change_frames));
  if (!(change_level > 0 && change_level < 255))
    fail("change_level must be in (0, 255), got " + number_text(change_level));
  if (!(background_ratio > 0 && background_ratio <= 1))
    fail("background_ratio must be in (0, 1], got " + number_text(background_ratio));
  if (!(start_motion >= 0 && start_motion <= 100))
    fail("start_motion must be in [0, 100], got " + number_text(start_motion));
  if (!(start_texture >= 0 && start_texture <= 100))
    fail("start_texture must be in [0, 100], got " + number_text(start_texture));
  if (!(start_reach >= 0 && start_reach <= 100))
    fail("start_reach must be in [0, 100], got " + number_text(start_reach));
  if (!(merge_overlap > 0 && merge_overlap <= 1))
    fail("merge_overlap must be in (0, 1], got " + number_text(merge_overlap));
}

namespace {

double share_of(const cv::Mat& integral, const cv::Mat& mask, int scale, const cv::Rect2f& box) {
  if (integral.empty() || !(box.width > 0) || !(box.height > 0)) return 0;
  const double s = scale;
  const int x0 = std::clamp(static_cast<int>(std::floor(box.x / s)), 0, mask.cols);
  const int y0 = std::clamp(static_cast<int>(std::floor(box.y / s)), 0, mask.rows);
  const int x1 = std::clamp(static_cast<int>(std::ceil((box.x + box.width) / s)), 0, mask.cols);
  const int y1 = std::clamp(static_cast<int>(std::ceil((box.y + box.height) / s)), 0, mask.rows);
  if (x1 <= x0 || y1 <= y0) return 0;
  const int sum = integral.at<int>(y1, x1) - integral.at<int>(y0, x1) - integral.at<int>(y1, x0) +
                  integral.at<int>(y0, x0);
  return static_cast<double>(sum) / (static_cast<double>(x1 - x0) * (y1 - y0));
}

}  // namespace

double Foreground::moving_share(const cv::Rect2f& box) const {
  return share_of(integral, mask, scale, box);
}

double Foreground::changed_share(const cv::Rect2f& box) const {
  return changed.empty() ? 1.0 : share_of(changed, mask, scale, box);
}

namespace {

// Per pixel (model resolution): frames in a row it was foreground without changing (ghost
// absorption); whether it settled during the scene start; whether it is held as background, and
// the gray level it was absorbed at.
struct PixelState {
  cv::Mat quiet, settled, absorbed, absorbed_gray;
  long long frames = 0;  // frames seen with a change mask
};

// A neighbourhood that moved less than this (model pixels) since `change_frames` back stood still.
constexpr double kStillShift = 0.5;
// A window changed by less than this many times the median window's change did not move.
constexpr float kNoiseRatio = 9;
// motion_state's window (7) and its blur's reach (2 on each side).
constexpr int kReach = 11;

}  // namespace

struct MotionDetector::Impl {
  // Shadows are labelled (127) and then count as background: a pedestrian's or a car's shadow
  // is not the object, and would merge neighbours into one blob. A shadow part that the
  // foreground surrounds is the object's own grey body, not a shadow (shadow_parts.hpp).
  explicit Impl(const MotionDetectorParams& p)
      : model(BandedMog2Params{p.history, p.var_threshold, p.shadows, p.shadow_threshold,
                               p.background_ratio}) {}
  BandedMog2 model;
  cv::Size frame_size;
  int scale = 1;
  cv::Mat small, raw;
  std::vector<cv::Mat> grays;  // the last change_frames + 1 gray frames (model resolution), a ring
  long long observed = 0;
  PixelState pixels;
};

namespace {

// Ghost absorption, ViBe-style. Per pixel, `quiet` counts the frames in a row it was
// foreground without changing (`changed` 0). A connected part of the foreground in which (almost)
// no pixel changed within the last `frames` frames is a ghost (background uncovered where an
// object stood when the model learnt it) or an object that stopped: its pixels are taken into
// the background at once, at their present gray level, and leave `mask`. An absorbed pixel
// comes back when its gray level moves more than `level` from that value (something new stands
// there) or the model itself calls it background. A moving object always changes somewhere (its
// leading and trailing edges), so none of its parts is absorbed, however uniform its body.
// Returns the count of absorbed pixels.
//
// Motion of each pixel's neighbourhood (7x7) between `old` and `gray`: 2 (moved) where the
// change is more than a shift of `shift` pixels would make, 1 (stood still) where the
// neighbourhood is textured in every direction and changed less than that, 0 where it cannot
// tell (too little texture, or a change above that bound but within the camera's noise: it
// proves neither). With I the image, G its structure tensor over the window and d the shift, the
// change is sum (grad I . d)^2 = d'Gd >= lambda_min(G) |d|^2: a sum of squared differences under
// shift^2 lambda_min bounds the shift under `shift` (noise only adds to it, so a noisy or weak
// texture reads as moved or unknown, never as still). Only the bound proves stillness: a weakly
// textured body that moved 10 px changes by more than the bound but less than the noise guard,
// and read as still it was absorbed (a moving object's box shrank).
cv::Mat motion_state(const cv::Mat& gray, const cv::Mat& old, double shift) {
  cv::Mat now, before;
  gray.convertTo(now, CV_32F);
  old.convertTo(before, CV_32F);
  cv::GaussianBlur(now, now, {0, 0}, 1.0);
  cv::GaussianBlur(before, before, {0, 0}, 1.0);
  cv::Mat ix, iy, d;
  cv::Sobel(now, ix, CV_32F, 1, 0, 3, 1.0 / 8);
  cv::Sobel(now, iy, CV_32F, 0, 1, 3, 1.0 / 8);
  cv::subtract(now, before, d);
  const cv::Size window(7, 7);
  cv::Mat sxx, syy, sxy, sdd;
  cv::boxFilter(ix.mul(ix), sxx, CV_32F, window, {-1, -1}, false);
  cv::boxFilter(iy.mul(iy), syy, CV_32F, window, {-1, -1}, false);
  cv::boxFilter(ix.mul(iy), sxy, CV_32F, window, {-1, -1}, false);
  cv::boxFilter(d.mul(d), sdd, CV_32F, window, {-1, -1}, false);
  const float floor = static_cast<float>(window.area());  // gradient 1 gray level a pixel
  const float s2 = static_cast<float>(shift * shift);
  // The camera's noise: most of a fixed camera's view stands still, so the median change of a
  // window is noise; a change under kNoiseRatio times that is no motion.
  std::vector<float> changes(sdd.begin<float>(), sdd.end<float>());
  const auto middle = changes.begin() + static_cast<std::ptrdiff_t>(changes.size() / 2);
  std::nth_element(changes.begin(), middle, changes.end());
  const float noise = kNoiseRatio * std::max(*middle, floor);  // at least 1 gray level
  cv::Mat state(gray.size(), CV_8U);
  for (int y = 0; y < state.rows; ++y) {
    const float* a = sxx.ptr<float>(y);
    const float* b = syy.ptr<float>(y);
    const float* c = sxy.ptr<float>(y);
    const float* e = sdd.ptr<float>(y);
    std::uint8_t* out = state.ptr<std::uint8_t>(y);
    for (int x = 0; x < state.cols; ++x) {
      const float half = 0.5f * (a[x] + b[x]);
      const float diff = 0.5f * (a[x] - b[x]);
      const float lmin = half - std::sqrt(diff * diff + c[x] * c[x]);
      if (e[x] > s2 * std::max(lmin, floor) && e[x] > noise)
        out[x] = 2;
      else if (lmin >= floor && e[x] <= s2 * lmin)
        out[x] = 1;
      else
        out[x] = 0;  // a change too small for the camera's noise proves no stillness either
    }
  }
  return state;
}

void split_blob(const cv::Mat& labels, const cv::Mat& mask, int label, cv::Rect box, double valley,
                double min_part_share, int depth, std::vector<cv::Rect>& out);

// Scene start's fill: the pixels of `moving` (neighbourhood moved, not settled) that the model
// calls background, inside the boxes of the objects the foreground holds (the uncovered
// background taken out): the holes where the model learnt the object itself, never beyond it (a
// shadow, a soft edge, the place it left). Each component of the foreground splits at the
// valleys of its column profile as detect_objects splits it (two people side by side), and
// nothing is filled within half a closing of a cut: the fill never bridges two neighbours, however
// much the background between them changed (it changes as they walk).
void fill_start_holes(cv::Mat& mask, cv::Mat& moving, const cv::Mat& settled, const cv::Mat& gray,
                      const cv::Mat& old, double level, const MotionDetectorParams& params) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  const int margin = std::max(1, params.close / 2);
  cv::Mat inside = cv::Mat::zeros(mask.size(), CV_8U);
  for (int i = 1; i < n; ++i) {
    const cv::Rect whole(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                         stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
    std::vector<cv::Rect> parts;
    split_blob(labels, mask, i, whole, params.split_valley, params.split_width, 0, parts);
    for (const cv::Rect& r : parts) {  // left to right; a side at a cut gives up the margin
      const int l = r.x > whole.x ? r.x + margin : r.x;
      const int e = r.br().x < whole.br().x ? r.br().x - margin : r.br().x;
      if (e > l) inside(cv::Rect(l, r.y, e - l, r.height)).setTo(255);
    }
  }
  moving &= inside;
  moving.setTo(0, settled);
  cv::Mat weak;  // and changed itself, by half the change level
  cv::absdiff(gray, old, weak);
  cv::threshold(weak, weak, level / 2, 255, cv::THRESH_BINARY);
  moving &= weak;
  mask |= moving;
}

// Scene start (the first `start` frames, > 0): the model learnt its first frame as background,
// the objects that moved in it included. There, until the pixel is settled: where its
// neighbourhood moved (motion_state against `old`, less the window's reach) it is foreground
// whatever the model says (the model holds the object that passed there); a foreground pixel
// that did not change and whose neighbourhood provably stood still is background such an
// object uncovered (it does not move; an object's body does, however uniform its colour to the
// change test): absorbed like a ghost at once, and settled. After the start the model has
// learnt more than its first frame and every pixel is left to it.
long long absorb_ghosts(cv::Mat& mask, const cv::Mat& gray, const cv::Mat& old,
                        const cv::Mat& changed, const cv::Mat& flow_motion, const cv::Mat& textured,
                        int scale, const MotionDetectorParams& params, PixelState& st) {
  const int frames = params.ghost_frames, start_frames = params.start_frames;
  const double level = params.change_level;
  if (st.quiet.size() != mask.size()) {
    st.quiet = cv::Mat::zeros(mask.size(), CV_16U);
    st.settled = cv::Mat::zeros(mask.size(), CV_8U);
    st.absorbed = cv::Mat::zeros(mask.size(), CV_8U);
    st.absorbed_gray = cv::Mat::zeros(mask.size(), CV_8U);
  }
  const bool start = ++st.frames <= start_frames;
  const bool by_flow = start && !flow_motion.empty();
  cv::Mat motion, moving;
  if (by_flow) {
    // The flow tells each pixel's own motion, less the reach of its window, and a still pixel is
    // background whether or not it changed lately (the object that stood there has just left).
    // Motion counts only in a textured window: elsewhere LK keeps the coarser levels' motion (a
    // uniform road beside a walker takes the walker's motion). Stillness does not need texture:
    // the coarser levels of a uniform body moving carry its motion, those of background none.
    motion = detail::flow_motion_state(flow_motion, params.start_motion);
    motion.setTo(0, (motion == 2) & ~textured);
    cv::compare(motion, 2, moving, cv::CMP_EQ);
    const int reach = static_cast<int>(std::lround(params.start_reach / scale));
    if (reach > 0)
      cv::erode(moving, moving,
                cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
  } else if (start) {
    motion = motion_state(gray, old, kStillShift);
    // Where it moved, less the reach of the window and the blur beyond the moving pixels.
    cv::compare(motion, 2, moving, cv::CMP_EQ);
    const cv::Mat reach = cv::getStructuringElement(cv::MORPH_RECT, {kReach, kReach});
    cv::erode(moving, moving, reach);
  }
  const int limit = static_cast<int>(level);
  for (int y = 0; y < mask.rows; ++y) {
    std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const std::uint8_t* g = gray.ptr<std::uint8_t>(y);
    const std::uint8_t* c = changed.ptr<std::uint8_t>(y);
    std::uint16_t* q = st.quiet.ptr<std::uint16_t>(y);
    std::uint8_t* se = st.settled.ptr<std::uint8_t>(y);
    std::uint8_t* a = st.absorbed.ptr<std::uint8_t>(y);
    std::uint8_t* ag = st.absorbed_gray.ptr<std::uint8_t>(y);
    const std::uint8_t* mv = start ? motion.ptr<std::uint8_t>(y) : nullptr;
    for (int x = 0; x < mask.cols; ++x) {
      if (a[x] != 0) {
        if (m[x] != 0 && std::abs(static_cast<int>(g[x]) - ag[x]) <= limit)
          m[x] = 0;
        else
          a[x] = 0;
      }
      if (start && m[x] != 0 && mv[x] == 1 && (by_flow || (se[x] == 0 && c[x] == 0))) {
        se[x] = 1;  // absorbed at its gray level
        a[x] = 1;
        ag[x] = g[x];
        m[x] = 0;
      }
      if (m[x] == 0 || c[x] != 0)
        q[x] = 0;
      else if (q[x] < 65535)
        ++q[x];
    }
  }
  if (by_flow)
    mask |= moving;
  else if (start)
    fill_start_holes(mask, moving, st.settled, gray, old, level, params);
  if (frames <= 0) return cv::countNonZero(st.absorbed);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<int> active(static_cast<std::size_t>(n), 0);
  for (int y = 0; y < mask.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const std::uint16_t* q = st.quiet.ptr<std::uint16_t>(y);
    for (int x = 0; x < mask.cols; ++x)
      if (l[x] > 0 && q[x] < frames) ++active[static_cast<std::size_t>(l[x])];
  }
  std::vector<char> ghost(static_cast<std::size_t>(n), 0);
  for (int i = 1; i < n; ++i)
    ghost[static_cast<std::size_t>(i)] =
        active[static_cast<std::size_t>(i)] <= stats.at<int>(i, cv::CC_STAT_AREA) / 50 ? 1 : 0;
  long long count = 0;
  for (int y = 0; y < mask.rows; ++y) {
    std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const int* l = labels.ptr<int>(y);
    const std::uint8_t* g = gray.ptr<std::uint8_t>(y);
    std::uint16_t* q = st.quiet.ptr<std::uint16_t>(y);
    std::uint8_t* a = st.absorbed.ptr<std::uint8_t>(y);
    std::uint8_t* ag = st.absorbed_gray.ptr<std::uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (a[x] != 0) ++count;
      if (l[x] <= 0 || ghost[static_cast<std::size_t>(l[x])] == 0) continue;
      a[x] = 1;
      ag[x] = g[x];
      q[x] = 0;
      m[x] = 0;
      ++count;
    }
  }
  return count;
}

}  // namespace

MotionDetector::MotionDetector(const MotionDetectorParams& params)
    : params_(params), impl_(std::make_shared<Impl>(params)) {
  params_.validate();
}

bool wants_flow(const MotionDetectorParams& params, long long index) {
  return params.start_motion > 0 && index >= 1 && index <= params.start_frames;
}

bool MotionDetector::wants_flow() const {
  return tracking::wants_flow(params_, impl_->observed);
}

Foreground MotionDetector::observe(const cv::Mat& image, const flow::FlowResult* flow_back,
                                   const Executor* executor) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw Error("motion detector: frame must be 8-bit gray or BGR");
  Impl& s = *impl_;
  if (s.frame_size.empty()) {
    s.frame_size = image.size();
    s.scale = params_.work_width > 0
                  ? std::max(1, static_cast<int>(std::lround(static_cast<double>(image.cols) /
                                                             params_.work_width)))
                  : 1;
  } else if (image.size() != s.frame_size) {
    throw Error("motion detector: frame size " + number_text(image.cols) + "x" +
                number_text(image.rows) + " differs from the first frame's " +
                number_text(s.frame_size.width) + "x" + number_text(s.frame_size.height));
  }
  const cv::Mat* input = &image;
  if (s.scale > 1) {
    // A whole factor: INTER_AREA averages scale x scale blocks (cheap).
    cv::resize(image, s.small,
               cv::Size(std::max(1, image.cols / s.scale), std::max(1, image.rows / s.scale)), 0, 0,
               cv::INTER_AREA);
    input = &s.small;
  }
  s.model.apply(*input, s.raw, -1, executor);
  if (params_.shadows && params_.shadow_enclosed > 0)
    reclaim_enclosed_shadows(s.raw, params_.shadow_enclosed);
  ++s.observed;
  Foreground fg;
  fg.observed = s.observed;
  fg.scale = s.scale;
  fg.frame_size = s.frame_size;
  cv::threshold(s.raw, fg.mask, 200, 255, cv::THRESH_BINARY);  // shadows (127) out
  // Changed pixels: against the frame change_frames back (a ring of gray frames).
  const std::size_t ring = static_cast<std::size_t>(params_.change_frames) + 1;
  if (s.grays.size() != ring) s.grays.assign(ring, cv::Mat());
  cv::Mat& gray =
      s.grays[static_cast<std::size_t>((s.observed - 1) % static_cast<long long>(ring))];
  if (input->channels() == 3) {
    cv::cvtColor(*input, gray, cv::COLOR_BGR2GRAY);
  } else {
    input->copyTo(gray);
  }
  // While fewer frames have been seen, against the first one.
  const long long back = std::min<long long>(params_.change_frames, s.observed - 1);
  if (back >= 1) {
    const cv::Mat& old =
        s.grays[static_cast<std::size_t>((s.observed - 1 - back) % static_cast<long long>(ring))];
    cv::Mat diff;
    cv::absdiff(gray, old, diff);
    cv::threshold(diff, diff, params_.change_level, 1, cv::THRESH_BINARY);
    cv::Mat textured;
    const bool flow_given = params_.start_motion > 0 && s.observed - 1 <= params_.start_frames &&
                            flow_back != nullptr && !flow_back->flow.empty();
    if (flow_given) {
      const flow::FlowResult& fb = *flow_back;
      if (fb.flow.type() != CV_32FC2 || fb.flow.size() != s.frame_size ||
          fb.confidence.type() != CV_32F || fb.confidence.size() != s.frame_size)
        throw Error("motion detector: the flow must be CV_32FC2 with its confidence, frame-sized");
      fg.motion = detail::relative_motion(fb.flow, fb.confidence, gray.size(),
                                          params_.start_texture, textured);
    }
    if (params_.ghost_frames > 0 || params_.start_frames > 0) {
      fg.absorbed =
          absorb_ghosts(fg.mask, gray, old, diff, fg.motion, textured, s.scale, params_, s.pixels);
      if (!fg.motion.empty())
        fg.motion.setTo(cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()), ~textured);
    }
    cv::integral(diff, fg.changed, CV_32S);
  }
  if (params_.open > 0) {
    cv::morphologyEx(fg.mask, fg.mask, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, {params_.open, params_.open}));
  }
  cv::Mat ones;
  cv::threshold(fg.mask, ones, 0, 1, cv::THRESH_BINARY);
  cv::integral(ones, fg.integral, CV_32S);
  return fg;
}

namespace {

bool stacked(const cv::Rect2f& a, const cv::Rect2f& b, double join_gap) {
  if (join_gap <= 0) return false;
  const double overlap_x = std::min(a.x + a.width, b.x + b.width) - std::max(a.x, b.x);
  if (overlap_x < 0.5 * std::min(a.width, b.width)) return false;
  const double gap = std::max(a.y, b.y) - std::min(a.y + a.height, b.y + b.height);
  return gap <= join_gap * std::max(a.height, b.height);
}

// Splits the component `label` over `box` (work resolution) at valleys of its column profile of
// moving pixels (`mask`, before the closing bridged the gaps between neighbours: each column's
// extent from its first to its last moving pixel); appends the parts' tight boxes.
void split_blob(const cv::Mat& labels, const cv::Mat& mask, int label, cv::Rect box, double valley,
                double min_part_share, int depth, std::vector<cv::Rect>& out) {
  // Per column, the rows from its first to its last moving pixel: a hole inside an object (a
  // window, a patch the model takes for background) leaves its column's extent whole and makes
  // no valley; the background between two objects does.
  std::vector<int> first(static_cast<std::size_t>(box.width), -1), cols(first.size(), 0);
  int top = box.br().y, bottom = box.y - 1, left = box.br().x, right = box.x - 1;
  for (int y = box.y; y < box.br().y; ++y) {
    const int* row = labels.ptr<int>(y);
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    for (int x = box.x; x < box.br().x; ++x) {
      if (row[x] != label || m[x] == 0) continue;
      const auto c = static_cast<std::size_t>(x - box.x);
      if (first[c] < 0) first[c] = y;
      cols[c] = y - first[c] + 1;
      top = std::min(top, y);
      bottom = std::max(bottom, y);
      left = std::min(left, x);
      right = std::max(right, x);
    }
  }
  if (bottom < top) return;
  // Tight vertically only: the columns between a cut and the object are kept (on PETS09 the
  // wider parts match the annotated boxes better).
  (void)left;
  (void)right;
  box = cv::Rect(box.x, top, box.width, bottom - top + 1);
  const int min_part = std::max(2, static_cast<int>(box.height * min_part_share));
  int best = -1;
  double best_ratio = valley;
  if (depth < 4 && valley > 0 && box.width >= 2 * min_part) {
    std::vector<int> left_peak(cols.size()), right_peak(cols.size());
    int peak = 0;
    for (std::size_t i = 0; i < cols.size(); ++i)
      left_peak[i] = peak = std::max(peak, cols[i]);
    peak = 0;
    for (std::size_t i = cols.size(); i-- > 0;)
      right_peak[i] = peak = std::max(peak, cols[i]);
    for (int x = min_part; x <= box.width - min_part; ++x) {
      const std::size_t i = static_cast<std::size_t>(x);
      const int lo = std::min(left_peak[i - 1], i + 1 < cols.size() ? right_peak[i + 1] : 0);
      if (lo <= 0) continue;
      const double ratio = static_cast<double>(cols[i]) / lo;
      if (ratio < best_ratio) {
        best_ratio = ratio;
        best = x;
      }
    }
  }
  if (best < 0) {
    out.push_back(box);
    return;
  }
  split_blob(labels, mask, label, cv::Rect(box.x, box.y, best, box.height), valley, min_part_share,
             depth + 1, out);
  split_blob(labels, mask, label, cv::Rect(box.x + best, box.y, box.width - best, box.height),
             valley, min_part_share, depth + 1, out);
}

}  // namespace

std::vector<cv::Rect2f> merge_nested(std::vector<cv::Rect2f> boxes, double overlap,
                                     double join_gap) {
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < boxes.size() && !merged; ++j) {
        const double inter = (boxes[i] & boxes[j]).area();
        const double smaller = std::min(boxes[i].area(), boxes[j].area());
        if ((smaller > 0 && inter >= overlap * smaller) || stacked(boxes[i], boxes[j], join_gap)) {
          boxes[i] = boxes[i] | boxes[j];
          boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
      }
    }
  }
  return boxes;
}

double smallest_object(const MotionDetectorParams& params, int scale) {
  const double model_pixel = static_cast<double>(scale) * scale;
  return params.min_model_area > 0 ? std::min(params.min_area, params.min_model_area * model_pixel)
                                   : params.min_area;
}

std::vector<Detection> detect_objects(const Foreground& fg, const MotionDetectorParams& params) {
  std::vector<Detection> out;
  if (fg.empty() || (fg.observed <= params.warmup && fg.motion.empty())) return out;
  // A fresh buffer: the closing must not write into fg.mask (shared, read by other threads).
  cv::Mat mask;
  if (params.close <= 0) mask = fg.mask;
  if (params.close > 0) {
    const int h = params.close_h > 0 ? params.close_h : params.close;
    cv::morphologyEx(fg.mask, mask, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, {params.close, h}));
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  const float s = static_cast<float>(fg.scale);
  const double min_area = smallest_object(params, fg.scale);
  const double min_small = min_area / (static_cast<double>(fg.scale) * fg.scale);
  // The boxes of distinct motions are not merged with the others: two objects crossing overlap.
  std::vector<cv::Rect2f> boxes, by_motion;
  for (int i = 1; i < n; ++i) {
    const int w = stats.at<int>(i, cv::CC_STAT_WIDTH), h = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    // Speckle that survived the opening is dropped before the merge.
    if (static_cast<double>(w) * h < 0.25 * min_small) continue;
    std::vector<cv::Rect> parts;
    const cv::Rect whole(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP), w,
                         h);
    const int min_pixels = std::max(8, static_cast<int>(0.25 * min_small));
    if (!fg.motion.empty() &&
        detail::split_by_motion(labels, fg.mask, fg.motion, i, whole, params.start_motion,
                                min_pixels, params.merge_overlap, parts)) {
      for (const cv::Rect& r : parts)
        by_motion.emplace_back(static_cast<float>(r.x) * s, static_cast<float>(r.y) * s,
                               static_cast<float>(r.width) * s, static_cast<float>(r.height) * s);
      continue;
    } else if (params.split_valley > 0) {
      split_blob(labels, fg.mask, i, whole, params.split_valley, params.split_width, 0, parts);
    } else {
      parts.push_back(whole);
    }
    for (const cv::Rect& r : parts) {
      boxes.emplace_back(static_cast<float>(r.x) * s, static_cast<float>(r.y) * s,
                         static_cast<float>(r.width) * s, static_cast<float>(r.height) * s);
    }
  }
  const cv::Rect2f frame(0.f, 0.f, static_cast<float>(fg.frame_size.width),
                         static_cast<float>(fg.frame_size.height));
  boxes = merge_nested(std::move(boxes), params.merge_overlap, params.join_gap);
  boxes.insert(boxes.end(), by_motion.begin(), by_motion.end());
  for (const cv::Rect2f& b : boxes) {
    const cv::Rect2f box = b & frame;
    if (box.area() < min_area) continue;
    out.push_back({box, (box.tl() + box.br()) * 0.5f, box.area()});
  }
  std::sort(out.begin(), out.end(),
            [](const Detection& a, const Detection& b) { return a.score > b.score; });
  return out;
}

}  // namespace roiflow::tracking
