#include "tracking/global_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"
#include "tracking/banded_mog2.hpp"
#include "tracking/template_search.hpp"

namespace roiflow::tracking {
namespace {

// Similarity = weighted mean of colour, shape and size agreement. Colour is the
// most telling cue for a rigid object seen from a fixed camera; the shape of a
// foreground silhouette is the noisiest (it merges with shadows and
// neighbours), so it weighs least.
constexpr double kColourWeight = 0.5;
constexpr double kShapeWeight = 0.2;
constexpr double kSizeWeight = 0.3;
// Candidates whose similarity is within this of the best are told apart by
// their distance to the expected position: such small differences are noise,
// the position is not.
constexpr double kTieBand = 0.05;
// The foreground must cover this share of a target box for its silhouette to
// describe the target (otherwise the box was given by hand and the silhouette
// belongs to something else).
constexpr double kMinForegroundShare = 0.3;
constexpr int kGrayBins = 32;
constexpr int kColourBins = 8;   // per channel: 8^3 bins, coarse enough for lighting changes
constexpr int kCoarseSide = 12;  // see by_appearance()
constexpr std::size_t kColourLooks = 4;  // recent colour looks kept (remember_colour)
constexpr int kHueBins = 12;             // colour looks: hue and saturation bins
constexpr int kSatBins = 4;
constexpr int kHuUsed = 4;  // the higher Hu moments are dominated by contour noise

void check_image(const cv::Mat& image, const char* what) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw Error(std::string("global detector: ") + what + " must be 8-bit gray or BGR, got " +
                (image.empty() ? std::string("an empty image") : cv::typeToString(image.type())));
  }
}

cv::Mat to_gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Normalised (sum 1) histogram of `image` where `mask` is set (all of it when
// empty): gray levels for gray images, joint B, G, R for colour ones.
cv::Mat histogram(const cv::Mat& image, const cv::Mat& mask) {
  cv::Mat hist;
  const float range[] = {0.f, 256.f};
  if (image.channels() == 1) {
    const int channels[] = {0};
    const int bins[] = {kGrayBins};
    const float* ranges[] = {range};
    cv::calcHist(&image, 1, channels, mask, hist, 1, bins, ranges);
  } else {
    const int channels[] = {0, 1, 2};
    const int bins[] = {kColourBins, kColourBins, kColourBins};
    const float* ranges[] = {range, range, range};
    cv::calcHist(&image, 1, channels, mask, hist, 3, bins, ranges);
  }
  const double total = cv::sum(hist)[0];
  if (total > 0) hist /= total;
  return hist;
}

// Hue and saturation (lighting changes move the value most), or the gray levels of a gray image;
// normalised to sum 1.
cv::Mat hue_histogram(const cv::Mat& image) {
  if (image.channels() == 1) return histogram(image, cv::Mat());
  cv::Mat hsv, hist;
  cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
  const int channels[] = {0, 1};
  const int bins[] = {kHueBins, kSatBins};
  const float hue[] = {0.f, 180.f};
  const float sat[] = {0.f, 256.f};
  const float* ranges[] = {hue, sat};
  cv::calcHist(&hsv, 1, channels, cv::Mat(), hist, 2, bins, ranges);
  const double total = cv::sum(hist)[0];
  if (total > 0) hist /= total;
  return hist;
}

using Hu = std::array<double, kHuUsed>;

// Hu moments of a silhouette's outline, as signed decades (log10), the scale on
// which they are compared (they span many orders of magnitude).
Hu hu_of(const std::vector<cv::Point>& contour) {
  double h[7];
  cv::HuMoments(cv::moments(contour), h);
  Hu out{};
  for (int i = 0; i < kHuUsed; ++i) {
    out[i] = h[i] == 0 ? 0.0 : std::copysign(std::log10(std::abs(h[i])), h[i]);
  }
  return out;
}

double shape_similarity(const Hu& a, const Hu& b) {
  double d = 0;
  for (int i = 0; i < kHuUsed; ++i)
    d += std::abs(a[i] - b[i]);
  return std::exp(-d / kHuUsed);
}

struct Signature {
  cv::Mat hist;
  int channels = 0;
  std::optional<Hu> hu;  // none when the target's silhouette is unknown
};

// One foreground object: the public part and what its signature needs.
struct Blob {
  Detection detection;
  std::vector<cv::Point> contour;  // at the model's resolution
};

}  // namespace

void GlobalDetectorParams::validate() const {
  if (history < 2)
    throw Error("global detector: history must be >= 2, got " + number_text(history));
  if (warmup < 0) throw Error("global detector: warmup must be >= 0, got " + number_text(warmup));
  if (work_width < 0) {
    throw Error("global detector: work_width must be >= 0, got " + number_text(work_width));
  }
  if (!(min_area >= 0) || !std::isfinite(min_area)) {
    throw Error("global detector: min_area must be >= 0, got " + number_text(min_area));
  }
  if (!(min_score > 0 && min_score < 1)) {
    throw Error("global detector: min_score must be in (0, 1), got " + number_text(min_score));
  }
  if (appearance_scales.empty()) throw Error("global detector: appearance_scales is empty");
  for (double s : appearance_scales) {
    if (!(s > 0) || !std::isfinite(s)) {
      throw Error("global detector: appearance scales must be positive, got " + number_text(s));
    }
  }
}

struct GlobalDetector::Impl {
  GlobalDetectorParams params;
  std::optional<BandedMog2> model;  // MOG2 (banded_mog2.hpp: one band, no executor here)
  cv::Size frame_size;              // of the first observed frame
  cv::Size work_size;
  cv::Point2d to_full{1, 1};  // full-resolution pixels per model pixel, in x and y
  long long observed = 0;
  cv::Mat fg_raw;  // MOG2's output for the last observed frame, at work_size
  // fg_raw cleaned by morphology, made when first asked for: the tracker's refreshes of the
  // model while it holds the target never look at it.
  mutable cv::Mat foreground;
  mutable bool foreground_stale = false;
  cv::Mat small;  // the shrunk frame, kept to reuse its buffer
  cv::Mat open_kernel, close_kernel;

  cv::Mat templ;  // gray appearance captured by set_target
  cv::Size2f size;
  Signature signature;
  cv::Mat hue;                        // the target's hue_histogram at set_target
  std::vector<cv::Mat> colour_looks;  // recent colour histograms (remember_colour), oldest first

  // Model-resolution rectangle covering a full-resolution one.
  cv::Rect to_work(const cv::Rect& r) const {
    const cv::Point tl(static_cast<int>(std::floor(r.x / to_full.x)),
                       static_cast<int>(std::floor(r.y / to_full.y)));
    const cv::Point br(static_cast<int>(std::ceil(r.br().x / to_full.x)),
                       static_cast<int>(std::ceil(r.br().y / to_full.y)));
    return cv::Rect(tl, br) & cv::Rect(cv::Point(), work_size);
  }

  // The filled silhouette of a model-resolution contour, as a mask over `box`
  // (full resolution) of the frame.
  cv::Mat silhouette(const std::vector<cv::Point>& contour, const cv::Rect& box) const {
    const cv::Rect work = to_work(box);
    cv::Mat small_mask = cv::Mat::zeros(work.size(), CV_8U);
    const std::vector<std::vector<cv::Point>> one{contour};
    cv::drawContours(small_mask, one, 0, cv::Scalar(255), cv::FILLED, cv::LINE_8, cv::noArray(), 0,
                     -work.tl());
    // Back to full resolution over the work rectangle, then the exact box cut
    // out of it.
    const cv::Rect full(static_cast<int>(std::lround(work.x * to_full.x)),
                        static_cast<int>(std::lround(work.y * to_full.y)),
                        static_cast<int>(std::lround(work.width * to_full.x)),
                        static_cast<int>(std::lround(work.height * to_full.y)));
    cv::Mat big;
    cv::resize(small_mask, big, full.size(), 0, 0, cv::INTER_NEAREST);
    cv::Mat out = cv::Mat::zeros(box.size(), CV_8U);
    const cv::Rect common = box & full;
    if (!common.empty()) big(common - full.tl()).copyTo(out(common - box.tl()));
    return out;
  }

  // The cleaned foreground mask of the last observed frame (empty before any).
  const cv::Mat& clean_foreground() const {
    if (foreground_stale) {
      // Opening removes isolated noise pixels; closing joins the pieces of one object that
      // the model split where the object looks like the background.
      cv::morphologyEx(fg_raw, foreground, cv::MORPH_OPEN, open_kernel);
      cv::morphologyEx(foreground, foreground, cv::MORPH_CLOSE, close_kernel);
      foreground_stale = false;
    }
    return foreground;
  }

  std::vector<Blob> blobs() const {
    std::vector<Blob> out;
    if (observed <= params.warmup || clean_foreground().empty()) return out;
    std::vector<std::vector<cv::Point>> contours;
    // CHAIN_APPROX_NONE: every edge pixel, so the barycentre is that of the
    // edge, not of the corners of a polygon.
    cv::findContours(foreground.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    const double pixel_area = to_full.x * to_full.y;
    for (auto& c : contours) {
      // The polygon through the edge pixels' centres misses half a pixel all
      // around.
      const double area = (cv::contourArea(c) + 0.5 * cv::arcLength(c, true) + 1) * pixel_area;
      if (area < params.min_area) continue;
      const cv::Rect r = cv::boundingRect(c);
      cv::Point2d sum(0, 0);
      for (const cv::Point& p : c)
        sum += cv::Point2d(p);
      const cv::Point2d mean = sum / static_cast<double>(c.size());
      Blob b;
      b.detection.box = cv::Rect2f(
          static_cast<float>(r.x * to_full.x), static_cast<float>(r.y * to_full.y),
          static_cast<float>(r.width * to_full.x), static_cast<float>(r.height * to_full.y));
      b.detection.barycentre = cv::Point2f(static_cast<float>((mean.x + 0.5) * to_full.x - 0.5),
                                           static_cast<float>((mean.y + 0.5) * to_full.y - 0.5));
      b.detection.score = area;
      b.contour = std::move(c);
      out.push_back(std::move(b));
    }
    std::sort(out.begin(), out.end(),
              [](const Blob& a, const Blob& b) { return a.detection.score > b.detection.score; });
    return out;
  }

  double similarity(const Signature& s, cv::Size2f candidate) const {
    const double colour = 1.0 - cv::compareHist(signature.hist, s.hist, cv::HISTCMP_BHATTACHARYYA);
    const double a = static_cast<double>(size.area()), b = static_cast<double>(candidate.area());
    const double scale = std::sqrt(std::min(a, b) / std::max(a, b));
    if (!signature.hu || !s.hu) {
      return (kColourWeight * colour + kSizeWeight * scale) / (kColourWeight + kSizeWeight);
    }
    return kColourWeight * colour + kShapeWeight * shape_similarity(*signature.hu, *s.hu) +
           kSizeWeight * scale;
  }

  std::optional<Detection> by_signature(const cv::Mat& image, cv::Point2f near) const {
    if (frame_size.empty()) return std::nullopt;
    if (image.size() != frame_size) {
      throw Error("global detector: frame size " + number_text(image.cols) + "x" +
                  number_text(image.rows) + " differs from the observed frames' " +
                  number_text(frame_size.width) + "x" + number_text(frame_size.height));
    }
    std::vector<Detection> candidates;
    for (Blob& b : blobs()) {
      const cv::Rect box = cv::Rect(b.detection.box) & cv::Rect(cv::Point(), image.size());
      if (box.empty()) continue;
      Signature s;
      s.hist = histogram(image(box), silhouette(b.contour, box));
      s.hu = hu_of(b.contour);
      b.detection.score = similarity(s, b.detection.box.size());
      candidates.push_back(b.detection);
    }
    if (candidates.empty()) return std::nullopt;
    double best = 0;
    for (const Detection& d : candidates)
      best = std::max(best, d.score);
    if (best < params.min_score) return std::nullopt;
    const Detection* pick = nullptr;
    double pick_distance = 0;
    for (const Detection& d : candidates) {
      if (d.score < best - kTieBand) continue;
      const double distance = cv::norm(d.barycentre - near);
      if (!pick || distance < pick_distance) pick = &d, pick_distance = distance;
    }
    return *pick;
  }

  std::optional<Detection> by_appearance(const cv::Mat& gray) const {
    const double rel = std::sqrt(static_cast<double>(size.area()) / templ.size().area());
    TemplateSearchParams search;
    // Coarser than template_search's default: each coarse pass covers the whole frame, once
    // per scale, and at 12 pixels a vehicle- or person-sized template still has its shape; the
    // fine pass around the coarse peak restores full-resolution accuracy.
    search.coarse_side = kCoarseSide;
    search.scales.clear();
    for (double k : params.appearance_scales)
      search.scales.push_back(k * rel);
    const TemplateMatch m =
        match_template(gray, templ, cv::Rect(0, 0, gray.cols, gray.rows), search);
    const double score = std::clamp(m.score, 0.0, 1.0);
    if (m.box.empty() || score < params.min_score) return std::nullopt;
    return Detection{m.box, (m.box.tl() + m.box.br()) * 0.5f, score};
  }
};

GlobalDetector::GlobalDetector(const GlobalDetectorParams& params)
    : impl_(std::make_shared<Impl>()) {
  params.validate();
  Impl& s = *impl_;
  s.params = params;
  // Shadows are not detected: a shadow is not the object, and labelling them
  // costs time.
  BandedMog2Params model_params;
  model_params.history = params.history;
  model_params.shadows = false;
  s.model.emplace(model_params);
  s.open_kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3));
  s.close_kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7));
}

void GlobalDetector::observe(const cv::Mat& image, double weight) {
  check_image(image, "frame");
  if (!(weight > 0) || !std::isfinite(weight)) {
    throw Error("global detector: observation weight must be > 0, got " + number_text(weight));
  }
  Impl& s = *impl_;
  if (s.frame_size.empty()) {
    s.frame_size = image.size();
    // Shrunk by a whole factor: INTER_AREA then averages k x k blocks, which costs ~0.2 ms at
    // 768x576; a fractional factor takes its general path (768x576 to 320x240: 3.8 ms, twice
    // MOG2 itself).
    const int factor =
        s.params.work_width > 0
            ? std::max(1, static_cast<int>(
                              std::lround(static_cast<double>(image.cols) / s.params.work_width)))
            : 1;
    s.work_size = cv::Size(std::max(1, image.cols / factor), std::max(1, image.rows / factor));
    s.to_full = cv::Point2d(static_cast<double>(image.cols) / s.work_size.width,
                            static_cast<double>(image.rows) / s.work_size.height);
  } else if (image.size() != s.frame_size) {
    throw Error("global detector: frame size " + number_text(image.cols) + "x" +
                number_text(image.rows) + " differs from the first frame's " +
                number_text(s.frame_size.width) + "x" + number_text(s.frame_size.height));
  }
  const cv::Mat* input = &image;
  if (s.work_size != s.frame_size) {
    cv::resize(image, s.small, s.work_size, 0, 0, cv::INTER_AREA);
    input = &s.small;
  }
  // A fixed learning rate, not MOG2's default 1/(2n) of the first frames: that one learns a
  // slow object into the background within a few frames. At 1/history the first frame's
  // content fades from the background in about a tenth of the history.
  s.model->apply(*input, s.fg_raw, std::min(1.0, weight / s.params.history));
  s.foreground_stale = true;
  ++s.observed;
}

std::vector<Detection> GlobalDetector::moving_objects() const {
  std::vector<Detection> out;
  for (Blob& b : impl_->blobs())
    out.push_back(b.detection);
  return out;
}

void GlobalDetector::set_target(const cv::Mat& image, const cv::Rect2f& box) {
  check_image(image, "target image");
  const cv::Rect r =
      cv::Rect(static_cast<int>(std::lround(box.x)), static_cast<int>(std::lround(box.y)),
               static_cast<int>(std::lround(box.width)),
               static_cast<int>(std::lround(box.height))) &
      cv::Rect(0, 0, image.cols, image.rows);
  if (r.width < 2 || r.height < 2) {
    throw Error("global detector: target box (" + number_text(box.x) + ", " + number_text(box.y) +
                ", " + number_text(box.width) + " x " + number_text(box.height) +
                ") leaves nothing inside the " + number_text(image.cols) + " x " +
                number_text(image.rows) + " frame");
  }
  Impl& s = *impl_;
  s.templ = to_gray(image(r)).clone();
  s.size =
      (box & cv::Rect2f(0.f, 0.f, static_cast<float>(image.cols), static_cast<float>(image.rows)))
          .size();

  // The silhouette, when the last observed frame's foreground describes this
  // box: the biggest foreground object that overlaps it.
  Signature sig;
  sig.channels = image.channels();
  cv::Mat mask;
  if (!s.clean_foreground().empty() && image.size() == s.frame_size) {
    double best_overlap = 0;
    for (const Blob& b : s.blobs()) {
      const double overlap = (cv::Rect2f(r) & b.detection.box).area();
      if (overlap <= best_overlap) continue;
      const cv::Mat m = s.silhouette(b.contour, r);
      if (cv::countNonZero(m) < kMinForegroundShare * r.area()) continue;
      best_overlap = overlap;
      mask = m;
      sig.hu = hu_of(b.contour);
    }
  }
  sig.hist = histogram(image(r), mask);
  s.signature = std::move(sig);
  s.hue = hue_histogram(image(r));
  s.colour_looks.clear();
}

namespace {

// The pixels of `box` inside `image` (rounded), empty when fewer than 2x2.
cv::Rect inside_pixels(const cv::Mat& image, const cv::Rect2f& box) {
  const cv::Rect r =
      cv::Rect(static_cast<int>(std::lround(box.x)), static_cast<int>(std::lround(box.y)),
               static_cast<int>(std::lround(box.width)),
               static_cast<int>(std::lround(box.height))) &
      cv::Rect(0, 0, image.cols, image.rows);
  return r.width < 2 || r.height < 2 ? cv::Rect() : r;
}

}  // namespace

double GlobalDetector::colour_similarity(const cv::Mat& image, const cv::Rect2f& box) const {
  const Impl& s = *impl_;
  if (s.templ.empty() || image.empty() || image.channels() != s.signature.channels) return -1;
  const cv::Rect r = inside_pixels(image, box);
  if (r.empty()) return -1;
  const cv::Mat h = hue_histogram(image(r));
  double best = 1.0 - cv::compareHist(s.hue, h, cv::HISTCMP_BHATTACHARYYA);
  for (const cv::Mat& look : s.colour_looks)
    best = std::max(best, 1.0 - cv::compareHist(look, h, cv::HISTCMP_BHATTACHARYYA));
  return best;
}

void GlobalDetector::remember_colour(const cv::Mat& image, const cv::Rect2f& box) {
  Impl& s = *impl_;
  if (s.templ.empty() || image.empty() || image.channels() != s.signature.channels) return;
  const cv::Rect r = inside_pixels(image, box);
  if (r.empty()) return;
  if (s.colour_looks.size() >= kColourLooks) s.colour_looks.erase(s.colour_looks.begin());
  s.colour_looks.push_back(hue_histogram(image(r)));
}

bool GlobalDetector::has_target() const {
  return !impl_->templ.empty();
}

cv::Size2f GlobalDetector::target_size() const {
  return impl_->size;
}

void GlobalDetector::set_target_size(cv::Size2f size) {
  if (!(size.width > 0 && size.height > 0)) {
    throw Error("global detector: target size must be positive, got " + number_text(size.width) +
                " x " + number_text(size.height));
  }
  impl_->size = size;
}

std::optional<Detection> GlobalDetector::find_target(const cv::Mat& image, const cv::Mat& gray,
                                                     cv::Point2f near, bool by_appearance) const {
  if (!has_target()) return std::nullopt;
  const Impl& s = *impl_;
  if (by_appearance) {
    if (!gray.empty()) {
      if (gray.type() != CV_8UC1) {
        throw Error("global detector: gray must be 8-bit single-channel, got " +
                    cv::typeToString(gray.type()));
      }
      return s.by_appearance(gray);
    }
    check_image(image, "frame");
    return s.by_appearance(to_gray(image));
  }
  check_image(image, "frame");
  if (image.channels() != s.signature.channels) {
    throw Error("global detector: the target was captured from a " +
                number_text(s.signature.channels) + "-channel image, got a " +
                number_text(image.channels()) + "-channel one");
  }
  return s.by_signature(image, near);
}

}  // namespace roiflow::tracking
