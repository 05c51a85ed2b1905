#include "tracking/template_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#ifdef __AVX2__
#include <immintrin.h>
#endif
#include <opencv2/imgproc.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"

namespace roiflow::tracking {
namespace {

// Offset in (-0.5, 0.5) of a parabola's vertex through three equally spaced samples.
float parabola_peak(float left, float centre, float right) {
  const float denom = left - 2.f * centre + right;
  if (!(denom < 0.f)) return 0.f;
  return std::clamp(0.5f * (left - right) / denom, -0.5f, 0.5f);
}

// Above this many multiply-adds (positions x template pixels) OpenCV's matchTemplate, which
// correlates through the DFT, is faster than the direct sum; below it the DFT's set-up
// dominates (a 44x25 template over 9x9 positions: 0.075 ms in matchTemplate, 0.022 ms direct;
// over 17x16 0.092 vs 0.047; over 57x56 0.29 vs 0.38).
constexpr double kDirectLimit = 1e6;
// Share of a window's sum of squares (about the image mean) below which its variance counts
// as none.
constexpr double kFlat = 1e-7;

constexpr int kLanes = 8;

// cv::mean of a float single-channel image, the same double to the last bit as OpenCV 4's
// (checked on 100000 random windows of random sizes): per row (one row when the image is
// continuous), sixteen lanes summed in double (eight from the low half of each 16-float
// vector, eight from the high half), the lanes added in order, then the rest four at a time
// summed in float, then one at a time; times 1 / count. That is OpenCV's AVX-512 sum, which it
// dispatches on this build's machines; elsewhere its own sums differ by rounding, and the
// results here stay those of that machine. A tracker's searches call it on a few hundred pixels
// a dozen times a frame, where cv::mean's dispatch and iterator cost several times the sums.
double mean_of(const cv::Mat& image) {
  constexpr int kSumLanes = 16, kHalf = kSumLanes / 2;
  const bool continuous = image.isContinuous();
  const int rows = continuous ? 1 : image.rows;
  const int len = continuous ? static_cast<int>(image.total()) : image.cols;
  double s = 0;
  for (int y = 0; y < rows; ++y) {
    const float* src = image.ptr<float>(y);
    double lo[kHalf] = {}, hi[kHalf] = {};
    int x = 0;
    for (; x <= len - kSumLanes; x += kSumLanes) {
      for (int l = 0; l < kHalf; ++l) {
        lo[l] += static_cast<double>(src[x + l]);
        hi[l] += static_cast<double>(src[x + kHalf + l]);
      }
    }
    for (double v : lo)
      s += v;
    for (double v : hi)
      s += v;
    for (; x <= len - 4; x += 4)
      s += src[x] + src[x + 1] + src[x + 2] + src[x + 3];  // in float, as OpenCV adds them
    for (; x < len; ++x)
      s += src[x];
  }
  return image.total() > 0 ? s * (1. / static_cast<double>(image.total())) : 0.0;
}

// out[k] = sum over the template of t(r, c) * image(r, c) from at[k], k = 0..count-1 (at most 4):
// any four positions, in a row or not, both zero-padded to whole vectors of kLanes. Four
// positions at once share each template load and keep four independent sums in flight (one sum
// alone waits on its adds); a window a few positions wide fills its groups from the next rows.
void dot_windows(const float* const* at, int stride, const cv::Mat& t, int count, float* out) {
  const int w = t.cols;
#if defined(__AVX2__) && defined(__FMA__)
  // Four named accumulators, reduced all four at the end: indexing an array of them by the
  // runtime `count` would keep them in memory instead of registers.
  __m256 a0 = _mm256_setzero_ps(), a1 = _mm256_setzero_ps();
  __m256 a2 = _mm256_setzero_ps(), a3 = _mm256_setzero_ps();
  const float *in0 = at[0], *in1 = at[1], *in2 = at[2], *in3 = at[3];
  for (int r = 0; r < t.rows; ++r) {
    const float* tr = t.ptr<float>(r);
    for (int c = 0; c < w; c += kLanes) {
      const __m256 tv = _mm256_loadu_ps(tr + c);
      a0 = _mm256_fmadd_ps(tv, _mm256_loadu_ps(in0 + c), a0);
      a1 = _mm256_fmadd_ps(tv, _mm256_loadu_ps(in1 + c), a1);
      a2 = _mm256_fmadd_ps(tv, _mm256_loadu_ps(in2 + c), a2);
      a3 = _mm256_fmadd_ps(tv, _mm256_loadu_ps(in3 + c), a3);
    }
    in0 += stride;
    in1 += stride;
    in2 += stride;
    in3 += stride;
  }
  // Horizontal sums of the four: two rounds of hadd leave (a0, a1, a2, a3) per 128-bit half.
  const __m256 h01 = _mm256_hadd_ps(a0, a1), h23 = _mm256_hadd_ps(a2, a3);
  const __m256 h = _mm256_hadd_ps(h01, h23);
  alignas(16) float sums[4];
  _mm_store_ps(sums, _mm_add_ps(_mm256_castps256_ps128(h), _mm256_extractf128_ps(h, 1)));
  for (int k = 0; k < count; ++k)
    out[k] = sums[k];
#else
  float acc[4][kLanes] = {};
  for (int r = 0; r < t.rows; ++r) {
    const float* tr = t.ptr<float>(r);
    for (int c = 0; c < w; c += kLanes)
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < kLanes; ++l)
          acc[k][l] += tr[c + l] * at[k][static_cast<std::ptrdiff_t>(r) * stride + c + l];
  }
  for (int k = 0; k < count; ++k) {
    out[k] = 0.f;
    for (float v : acc[k])
      out[k] += v;
  }
#endif
}

}  // namespace

namespace {

// Buffers of ccoeff_normed_direct kept per thread: a tracker calls it a few times per frame on
// a few-kilobyte image, and allocating them afresh each time cost more than the sums (glibc
// returns the freed top of the heap to the system and faults it back in on the next call).
struct DirectScratch {
  std::vector<float> image;        // centred, zero-padded rows
  std::vector<double> sum, sqsum;  // integral images of the centred image, (rows+1) x (cols+1)
};

// The image centred on `i_mean` into scratch.image (rows ipw floats apart, zero-padded past the
// end) and the integral images of its values and squares into scratch.sum and scratch.sqsum
// ((rows + 1) x (cols + 1)), for windows tw wide at nx positions a row.
void centre_and_integrate(const cv::Mat& image, float i_mean, int nx, int tw, int ipw,
                          DirectScratch& scratch) {
  const int iw = image.cols, ih = image.rows;
  const std::size_t sw = static_cast<std::size_t>(iw) + 1;
  scratch.sum.resize(sw * (ih + 1));
  scratch.sqsum.resize(sw * (ih + 1));
  std::fill_n(scratch.sum.begin(), sw, 0.0);
  std::fill_n(scratch.sqsum.begin(), sw, 0.0);
  // Integral images of the centred image. The window sums read only their columns [0, nx) and
  // [tw, iw]: between, each row's running sums are carried along but not summed down the rows.
  // kRows rows at a time: each row's running sums are a chain of dependent adds, so rows side
  // by side keep several chains in flight (the same adds in the same order per row as one row
  // at a time).
  const int gap0 = nx - 1;                  // x in [gap0, gap1): column x + 1 is not read
  const int gap1 = std::max(gap0, tw - 1);  //
  constexpr int kRows = 4;
  for (int y0 = 0; y0 < ih; y0 += kRows) {
    const int rows = std::min(kRows, ih - y0);
    const float* src[kRows];
    float* dst[kRows];
    double* s_row[kRows];
    double* q_row[kRows];
    double s[kRows] = {}, q[kRows] = {};
    for (int k = 0; k < kRows; ++k) {
      const int y = y0 + std::min(k, rows - 1);
      src[k] = image.ptr<float>(y);
      dst[k] = scratch.image.data() + static_cast<std::size_t>(y) * ipw;
      s_row[k] = scratch.sum.data() + (y + 1) * sw;
      q_row[k] = scratch.sqsum.data() + (y + 1) * sw;
      s_row[k][0] = 0.0;
      q_row[k][0] = 0.0;
    }
    const double* s_up = scratch.sum.data() + y0 * sw;
    const double* q_up = scratch.sqsum.data() + y0 * sw;
    // Columns [x0, x1) of the block's rows, summed down the rows when `down` says so.
    auto block = [&](auto down, int x0, int x1) {
      for (int x = x0; x < x1; ++x) {
        // Column x + 1 of the rows above, carried down in registers.
        double vs = 0, vq = 0;
        if constexpr (decltype(down)::value) {
          vs = s_up[x + 1];
          vq = q_up[x + 1];
        }
        for (int k = 0; k < kRows; ++k) {
          const float d = src[k][x] - i_mean;
          dst[k][x] = d;
          s[k] += d;
          q[k] += static_cast<double>(d) * d;
          if constexpr (decltype(down)::value) {
            vs += s[k];
            vq += q[k];
            s_row[k][x + 1] = vs;
            q_row[k][x + 1] = vq;
          }
        }
      }
    };
    // The last rows one at a time, the same way.
    auto row = [&](auto down, int k, int x0, int x1) {
      const double* su = k == 0 ? s_up : s_row[k - 1];
      const double* qu = k == 0 ? q_up : q_row[k - 1];
      for (int x = x0; x < x1; ++x) {
        const float d = src[k][x] - i_mean;
        dst[k][x] = d;
        s[k] += d;
        q[k] += static_cast<double>(d) * d;
        if constexpr (decltype(down)::value) {
          s_row[k][x + 1] = su[x + 1] + s[k];
          q_row[k][x + 1] = qu[x + 1] + q[k];
        }
      }
    };
    if (rows == kRows) {
      block(std::true_type{}, 0, gap0);
      block(std::false_type{}, gap0, gap1);
      block(std::true_type{}, gap1, iw);
    } else {
      for (int k = 0; k < rows; ++k) {
        row(std::true_type{}, k, 0, gap0);
        row(std::false_type{}, k, gap0, gap1);
        row(std::true_type{}, k, gap1, iw);
      }
    }
    for (int k = 0; k < rows; ++k)
      std::fill(dst[k] + iw, dst[k] + ipw, 0.f);
  }
}

}  // namespace

DirectTemplate::DirectTemplate(const cv::Mat& t) : templ(t) {
  if (t.type() != CV_32FC1 || t.empty()) {
    throw Error("template search: direct NCC needs a float template");
  }
  const int tw = t.cols, th = t.rows;
  // Centred on its mean: NCC does not change, and the float sums lose far less to rounding
  // than they would on raw intensities. Rows padded with zeros to whole vectors: each position's
  // dot product is then whole-vector multiply-adds, reduced once per position.
  stride = (tw + kLanes - 1) / kLanes * kLanes;
  rows.resize(static_cast<std::size_t>(th) * stride);
  const auto t_mean = static_cast<float>(mean_of(t));
  for (int y = 0; y < th; ++y) {
    const float* src = t.ptr<float>(y);
    float* dst = rows.data() + static_cast<std::size_t>(y) * stride;
    float acc = 0.f;
    for (int x = 0; x < tw; ++x) {
      dst[x] = src[x] - t_mean;
      acc += dst[x] * dst[x];
    }
    std::fill(dst + tw, dst + stride, 0.f);
    norm2 += acc;
  }
}

void ccoeff_normed_direct(const cv::Mat& image, const cv::Mat& templ, cv::Mat& response) {
  if (templ.type() != CV_32FC1 || templ.empty()) {
    throw Error("template search: direct NCC needs a float template no larger than the image");
  }
  ccoeff_normed_direct(image, DirectTemplate(templ), response);
}

void ccoeff_normed_direct(const cv::Mat& image, const DirectTemplate& prepared, cv::Mat& response) {
  const cv::Mat& templ = prepared.templ;
  if (image.type() != CV_32FC1 || templ.cols > image.cols || templ.rows > image.rows) {
    throw Error("template search: direct NCC needs a float template no larger than the image");
  }
  thread_local DirectScratch scratch;
  const int tw = templ.cols, th = templ.rows;
  const int iw = image.cols, ih = image.rows;
  const int nx = iw - tw + 1, ny = ih - th + 1;
  const double n = static_cast<double>(tw) * th;
  // The image centred on its mean like the template (DirectTemplate), its rows padded with
  // zeros past the end.
  const int twp = prepared.stride;
  const int ipw = iw + twp + 4;
  // Only what is read is written: zeroing whole buffers on every call cost as much as the sums
  // (the padding is zeroed row by row below; an integral image's first row and column here).
  scratch.image.resize(static_cast<std::size_t>(ih) * ipw);
  const cv::Mat tp(th, twp, CV_32F, const_cast<float*>(prepared.rows.data()));
  const cv::Mat ip(ih, ipw, CV_32F, scratch.image.data());
  const auto i_mean = static_cast<float>(mean_of(image));
  const double t_norm2 = prepared.norm2;
  const std::size_t sw = static_cast<std::size_t>(iw) + 1;
  centre_and_integrate(image, i_mean, nx, tw, ipw, scratch);
  response.create(ny, nx, CV_32F);
  // The positions in row-major order, four at a time (the last group repeats its last one).
  const int positions = nx * ny;
  float* res = response.ptr<float>(0);
  for (int p = 0; p < positions; p += 4) {
    const int count = std::min(4, positions - p);
    const float* at[4];
    for (int k = 0; k < 4; ++k) {
      const int q = p + std::min(k, count - 1);
      at[k] = ip.ptr<float>(q / nx) + q % nx;
    }
    dot_windows(at, ipw, tp, count, res + p);
  }
  for (int y = 0; y < ny; ++y) {
    float* out = response.ptr<float>(y);
    const double* s0 = scratch.sum.data() + y * sw;
    const double* s1 = scratch.sum.data() + (y + th) * sw;
    const double* q0 = scratch.sqsum.data() + y * sw;
    const double* q1 = scratch.sqsum.data() + (y + th) * sw;
    for (int x = 0; x < nx; ++x) {
      const double ws = s1[x + tw] - s1[x] - s0[x + tw] + s0[x];
      const double wq = q1[x + tw] - q1[x] - q0[x + tw] + q0[x];
      const double window_ss = wq - ws * ws / n;
      // A flat window (or template) has no defined NCC: 0, as OpenCV's rule gives for exact
      // zeros. "Flat" is relative to the image's own contrast, so rounding noise never scores.
      if (!(window_ss > kFlat * wq) || !(t_norm2 > 0)) {
        out[x] = 0.f;
        continue;
      }
      const double denom = std::sqrt(window_ss * t_norm2);
      double num = out[x];
      if (std::abs(num) < denom) {
        num /= denom;
      } else if (std::abs(num) < denom * 1.125) {
        num = num > 0 ? 1 : -1;
      } else {
        num = 0;
      }
      out[x] = static_cast<float>(num);
    }
  }
}

cv::Size scaled_size(const cv::Mat& templ, double scale) {
  return {std::max(1, static_cast<int>(std::lround(templ.cols * scale))),
          std::max(1, static_cast<int>(std::lround(templ.rows * scale)))};
}

cv::Mat resize_template(const cv::Mat& src, cv::Size size) {
  if (size == src.size()) return src;
  cv::Mat out;
  const bool shrink = size.area() < src.size().area();
  cv::resize(src, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

namespace {

bool prior_on(const MatchPrior& p) {
  return p.radius > 0 && p.penalty > 0;
}

// Throws roiflow::Error unless the prior's radius and penalty are >= 0.
void check_prior(const MatchPrior& prior) {
  if (!(prior.radius >= 0 && prior.penalty >= 0)) {
    throw Error("template search: the prior's radius and penalty must be >= 0");
  }
}

// Best full-resolution match of `templ` (already scaled; `prepared` when the caller has it) in
// `region` of `image`.
TemplateMatch match_one(const cv::Mat& image, const cv::Mat& templ, const cv::Rect& region,
                        const MatchPrior& prior = {}, const DirectTemplate* prepared = nullptr) {
  TemplateMatch best;
  if (region.width < templ.cols || region.height < templ.rows) return best;
  thread_local cv::Mat response;  // reused: see DirectScratch
  const double work = static_cast<double>(region.width - templ.cols + 1) *
                      (region.height - templ.rows + 1) * templ.total();
  if (image.depth() == CV_32F && work <= kDirectLimit) {
    if (prepared != nullptr) {
      ccoeff_normed_direct(image(region), *prepared, response);
    } else {
      ccoeff_normed_direct(image(region), templ, response);
    }
  } else {
    cv::matchTemplate(image(region), templ, response, cv::TM_CCOEFF_NORMED);
  }
  double max_value = 0;
  double ranked = 0;
  cv::Point at;
  if (prior_on(prior)) {
    // The centre of the match at response pixel (x, y), relative to the prior's.
    const float cx =
        static_cast<float>(region.x) + 0.5f * static_cast<float>(templ.cols) - prior.centre.x;
    const float cy =
        static_cast<float>(region.y) + 0.5f * static_cast<float>(templ.rows) - prior.centre.y;
    const auto k = static_cast<float>(prior.penalty / (prior.radius * prior.radius));
    ranked = -std::numeric_limits<double>::infinity();
    for (int y = 0; y < response.rows; ++y) {
      const float* row = response.ptr<float>(y);
      const float dy = cy + static_cast<float>(y);
      for (int x = 0; x < response.cols; ++x) {
        const float dx = cx + static_cast<float>(x);
        const float r = row[x] - k * (dx * dx + dy * dy);
        if (r > ranked) {
          ranked = r;
          at = {x, y};
        }
      }
    }
    max_value = response.at<float>(at);
  } else {
    cv::minMaxLoc(response, nullptr, &max_value, nullptr, &at);
    ranked = max_value;
  }
  if (!std::isfinite(max_value)) return best;
  float dx = 0.f, dy = 0.f;
  if (at.x > 0 && at.x + 1 < response.cols) {
    dx = parabola_peak(response.at<float>(at.y, at.x - 1), response.at<float>(at.y, at.x),
                       response.at<float>(at.y, at.x + 1));
  }
  if (at.y > 0 && at.y + 1 < response.rows) {
    dy = parabola_peak(response.at<float>(at.y - 1, at.x), response.at<float>(at.y, at.x),
                       response.at<float>(at.y + 1, at.x));
  }
  best.score = max_value;
  best.ranked = ranked;
  best.box =
      cv::Rect2f(static_cast<float>(region.x + at.x) + dx, static_cast<float>(region.y + at.y) + dy,
                 static_cast<float>(templ.cols), static_cast<float>(templ.rows));
  return best;
}

}  // namespace

TemplateMatch match_template(const cv::Mat& image, const DirectTemplate& templ,
                             const cv::Rect& search, const MatchPrior& prior) {
  if (image.empty()) throw Error("template search: empty image or template");
  if (image.type() != CV_32FC1) {
    throw Error("template search: a prepared template needs a float image, got " +
                cv::typeToString(image.type()));
  }
  check_prior(prior);
  const cv::Rect region = search & cv::Rect(0, 0, image.cols, image.rows);
  if (region.empty()) return {};
  const TemplateMatch m = match_one(image, templ.templ, region, prior, &templ);
  return m.score > -1 ? m : TemplateMatch{};
}

TemplateMatch match_template(const cv::Mat& image, const cv::Mat& templ, const cv::Rect& search,
                             const TemplateSearchParams& params, const MatchPrior& prior) {
  if (image.empty() || templ.empty()) throw Error("template search: empty image or template");
  if (image.channels() != 1 || templ.channels() != 1) {
    throw Error("template search: image and template must be single-channel");
  }
  if (image.depth() != templ.depth() || (image.depth() != CV_8U && image.depth() != CV_32F)) {
    throw Error("template search: image and template must both be 8-bit or both float, got " +
                cv::typeToString(image.type()) + " and " + cv::typeToString(templ.type()));
  }
  if (params.scales.empty()) throw Error("template search: no scales given");
  check_prior(prior);
  for (double s : params.scales) {
    if (!(s > 0.0) || !std::isfinite(s)) {
      throw Error("template search: scales must be positive, got " + std::to_string(s));
    }
  }
  const cv::Rect region = search & cv::Rect(0, 0, image.cols, image.rows);
  TemplateMatch best;
  if (region.empty()) return best;

  for (double scale : params.scales) {
    const cv::Size size = scaled_size(templ, scale);
    if (size.width > region.width || size.height > region.height) continue;
    const cv::Mat scaled = resize_template(templ, size);
    const int side = std::min(size.width, size.height);
    TemplateMatch m;
    if (params.coarse_side > 0 && side > params.coarse_side) {
      // Coarse pass over the whole region, then a window of a few coarse pixels at full size.
      const double f = static_cast<double>(params.coarse_side) / side;
      const cv::Size coarse_templ(std::max(1, static_cast<int>(std::lround(size.width * f))),
                                  std::max(1, static_cast<int>(std::lround(size.height * f))));
      const cv::Size coarse_region(std::max(1, static_cast<int>(std::lround(region.width * f))),
                                   std::max(1, static_cast<int>(std::lround(region.height * f))));
      if (coarse_templ.width > coarse_region.width || coarse_templ.height > coarse_region.height) {
        continue;
      }
      const cv::Mat small_image = resize_template(image(region), coarse_region);
      const MatchPrior small_prior{
          (prior.centre - cv::Point2f(region.tl())) * static_cast<float>(f), prior.radius * f,
          prior.penalty};
      const TemplateMatch coarse = match_one(small_image, resize_template(scaled, coarse_templ),
                                             cv::Rect(cv::Point(), coarse_region), small_prior);
      if (coarse.score <= -1) continue;
      const int pad = static_cast<int>(std::ceil(2.0 / f)) + 1;
      const cv::Rect window(region.x + static_cast<int>(std::lround(coarse.box.x / f)) - pad,
                            region.y + static_cast<int>(std::lround(coarse.box.y / f)) - pad,
                            size.width + 2 * pad, size.height + 2 * pad);
      m = match_one(image, scaled, window & region, prior);
    } else {
      m = match_one(image, scaled, region, prior);
    }
    if (m.score > -1 && (best.score <= -1 || m.ranked > best.ranked)) {
      best = m;
      best.scale = scale;
    }
  }
  return best;
}

}  // namespace roiflow::tracking
