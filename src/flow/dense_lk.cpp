#include "flow/dense_lk.hpp"

#include <algorithm>
#ifdef __AVX2__
#include <immintrin.h>
#endif
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "flow/error.hpp"

namespace roiflow::flow {

namespace {

// A window along one axis, as offsets from the pixel into the derivative grid. Outermost taps
// carry weight 1/2 when `half` (see the header on patch centring).
struct Window {
  int lo = 0;
  int hi = 0;
  bool half = false;
  int reach() const { return std::max(-lo, hi); }
};

Window make_window(int patch, bool half_pixel_grid) {
  const int h = patch / 2;
  const bool odd = (patch % 2) != 0;
  if (!half_pixel_grid) return odd ? Window{-h, h, false} : Window{-h, h, true};
  return odd ? Window{-h - 1, h, true} : Window{-h, h - 1, false};
}

// Sum of the window's weights at index i of an axis of n samples (the clipped window).
float window_weight(const Window& win, int i, int n) {
  const int a = std::max(0, i + win.lo), b = std::min(n - 1, i + win.hi);
  float w = static_cast<float>(b - a + 1);
  if (win.half) {
    if (i + win.lo >= 0) w -= 0.5f;
    if (i + win.hi <= n - 1) w -= 0.5f;
  }
  return w;
}

struct LevelProblem {
  const cv::Mat* i0 = nullptr;  // level images, full size
  const cv::Mat* i1 = nullptr;
  cv::Rect comp;  // where the flow is computed, level pixels
  Derivative derivative = Derivative::HornSchunck;
  Window win;
  float lambda = 0.f;
  float robust_inv_scale2 = 0.f;  // 1 / robust_scale^2, 0 = least squares
  std::vector<float> inv_cx;      // 1 / horizontal window weight per column
  std::vector<float> cy;          // vertical window weight per row
};

constexpr int kChannels = 5;  // gxx, gxy, gyy, bx, by

struct WarpedRow {
  int row = -1;
  std::vector<float> m, d, u, v;  // padded by one on each side (replicated)
};

// Row buffers of one RowIterator. They live per thread and keep their capacity, so the
// iterations of a level allocate nothing.
struct RowScratch {
  WarpedRow warp_cache[4];
  std::vector<float> ring, colsum, col, win, delta, zero_row, deriv;
  std::vector<int> ring_row_id;
};

RowScratch& thread_scratch() {
  thread_local RowScratch scratch;
  return scratch;
}

// Frame t+1 sampled bilinearly at x + flow(x) along one row (border replicated), returned
// as the mean with frame t, m = (I0 + I1w) / 2, and the difference d = I1w - I0. Written
// without branches so that the compiler can use gathers.
void warp_row(const cv::Mat& i1, const float* __restrict i0, int x0, int y, int w,
              const float* __restrict u, const float* __restrict v, float* __restrict m,
              float* __restrict d) {
  const float* __restrict base = i1.ptr<float>(0);
  const int step = static_cast<int>(i1.step1());
  const int dx1 = i1.cols > 1 ? 1 : 0, dy1 = i1.rows > 1 ? step : 0;
  const float xhi = static_cast<float>(i1.cols - 1), yhi = static_cast<float>(i1.rows - 1);
  const int ixmax = std::max(0, i1.cols - 2), iymax = std::max(0, i1.rows - 2);
  const float fy0 = static_cast<float>(y);
  for (int x = 0; x < w; ++x) {
    const float sx = std::min(std::max(static_cast<float>(x0 + x) + u[x], 0.f), xhi);
    const float sy = std::min(std::max(fy0 + v[x], 0.f), yhi);
    const int ix = std::min(static_cast<int>(sx), ixmax);
    const int iy = std::min(static_cast<int>(sy), iymax);
    const float fx = sx - static_cast<float>(ix), fy = sy - static_cast<float>(iy);
    const int idx = iy * step + ix;
    const float p00 = base[idx], p01 = base[idx + dx1];
    const float p10 = base[idx + dy1], p11 = base[idx + dy1 + dx1];
    const float top = p00 + fx * (p01 - p00);
    const float bot = p10 + fx * (p11 - p10);
    const float w1 = top + fy * (bot - top);
    m[x] = 0.5f * (i0[x] + w1);
    d[x] = w1 - i0[x];
  }
}

// Padding replicates the last column, so x + 1 is valid there and gives a zero step.
void hs_derivatives(const WarpedRow& a, const WarpedRow& b, int w, float* __restrict ix,
                    float* __restrict iy, float* __restrict it, float* __restrict ub,
                    float* __restrict vb) {
  const float* __restrict m0 = a.m.data() + 1;
  const float* __restrict m1 = b.m.data() + 1;
  const float* __restrict d0 = a.d.data() + 1;
  const float* __restrict d1 = b.d.data() + 1;
  const float* __restrict u0 = a.u.data() + 1;
  const float* __restrict u1 = b.u.data() + 1;
  const float* __restrict v0 = a.v.data() + 1;
  const float* __restrict v1 = b.v.data() + 1;
  for (int x = 0; x < w; ++x) {
    ix[x] = 0.5f * ((m0[x + 1] - m0[x]) + (m1[x + 1] - m1[x]));
    iy[x] = 0.5f * ((m1[x] - m0[x]) + (m1[x + 1] - m0[x + 1]));
    it[x] = 0.25f * (d0[x] + d0[x + 1] + d1[x] + d1[x + 1]);
    ub[x] = 0.25f * (u0[x] + u0[x + 1] + u1[x] + u1[x + 1]);
    vb[x] = 0.25f * (v0[x] + v0[x + 1] + v1[x] + v1[x + 1]);
  }
}

// Scharr (3x3) or central differences on the pixel grid, rows up / centre / down.
void grid_derivatives(bool scharr, const WarpedRow& up, const WarpedRow& centre,
                      const WarpedRow& down, int w, float* __restrict ix, float* __restrict iy,
                      float* __restrict it, float* __restrict ub, float* __restrict vb) {
  const float* __restrict mu = up.m.data() + 1;
  const float* __restrict mc = centre.m.data() + 1;
  const float* __restrict md = down.m.data() + 1;
  if (scharr) {
    constexpr float k = 1.f / 32.f;
    for (int x = 0; x < w; ++x) {
      ix[x] = k * (3.f * (mu[x + 1] - mu[x - 1]) + 10.f * (mc[x + 1] - mc[x - 1]) +
                   3.f * (md[x + 1] - md[x - 1]));
      iy[x] = k * (3.f * (md[x - 1] - mu[x - 1]) + 10.f * (md[x] - mu[x]) +
                   3.f * (md[x + 1] - mu[x + 1]));
    }
  } else {
    for (int x = 0; x < w; ++x) {
      ix[x] = 0.5f * (mc[x + 1] - mc[x - 1]);
      iy[x] = 0.5f * (md[x] - mu[x]);
    }
  }
  std::copy(centre.d.data() + 1, centre.d.data() + 1 + w, it);
  std::copy(centre.u.data() + 1, centre.u.data() + 1 + w, ub);
  std::copy(centre.v.data() + 1, centre.v.data() + 1 + w, vb);
}

// The five window terms of one derivative-grid row: Ix², IxIy, Iy² and Ix·r, Iy·r with
// r = Ix·ū + Iy·v̄ − It, the brightness equation linearised around the local flow (ū, v̄).
template <bool kRobust>
void emit_products(int w, const float* __restrict ix, const float* __restrict iy,
                   const float* __restrict it, const float* __restrict ub,
                   const float* __restrict vb, float inv_s2, float* __restrict out) {
  float* __restrict gxx = out;
  float* __restrict gxy = out + w;
  float* __restrict gyy = out + 2 * w;
  float* __restrict bx = out + 3 * w;
  float* __restrict by = out + 4 * w;
  for (int x = 0; x < w; ++x) {
    float wix = ix[x], wiy = iy[x];
    if constexpr (kRobust) {
      const float wgt = 1.f / (1.f + it[x] * it[x] * inv_s2);
      wix *= wgt;
      wiy *= wgt;
    }
    const float r = ix[x] * ub[x] + iy[x] * vb[x] - it[x];
    gxx[x] = wix * ix[x];
    gxy[x] = wix * iy[x];
    gyy[x] = wiy * iy[x];
    bx[x] = wix * r;
    by[x] = wiy * r;
  }
}

// out[i] = in[0] + ... + in[i].
void inclusive_prefix(const float* __restrict in, int n, float* __restrict out) {
  int i = 0;
  float carry = 0.f;
#ifdef __AVX2__
  __m256 vcarry = _mm256_setzero_ps();
  for (; i + 8 <= n; i += 8) {
    __m256 x = _mm256_loadu_ps(in + i);
    x = _mm256_add_ps(x, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(x), 4)));
    x = _mm256_add_ps(x, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(x), 8)));
    // Each 128-bit half now holds its own prefix; carry the low half's total into the high.
    const __m256 low_total = _mm256_permute_ps(x, _MM_SHUFFLE(3, 3, 3, 3));
    x = _mm256_add_ps(x, _mm256_permute2f128_ps(low_total, low_total, 0x08));
    x = _mm256_add_ps(x, vcarry);
    _mm256_storeu_ps(out + i, x);
    const __m256 last = _mm256_permute_ps(x, _MM_SHUFFLE(3, 3, 3, 3));
    vcarry = _mm256_permute2f128_ps(last, last, 0x11);
  }
  carry = _mm256_cvtss_f32(vcarry);
#endif
  for (; i < n; ++i) {
    carry += in[i];
    out[i] = carry;
  }
}

// The regularised 2x2 solve of one row: (G + lambda I) w = b + lambda w_old, with G and b
// the window means (sums times 1 / weight).
void solve_pixels(int w, const float* __restrict sums, const float* __restrict inv_cx, float inv_cy,
                  float lambda, const float* __restrict uo, const float* __restrict vo,
                  float* __restrict un, float* __restrict vn) {
  const float* __restrict sxx = sums;
  const float* __restrict sxy = sums + w;
  const float* __restrict syy = sums + 2 * w;
  const float* __restrict sbx = sums + 3 * w;
  const float* __restrict sby = sums + 4 * w;
  for (int x = 0; x < w; ++x) {
    const float n = inv_cx[x] * inv_cy;
    const float gxy = sxy[x] * n;
    const float a = sxx[x] * n + lambda, d = syy[x] * n + lambda;
    const float ex = sbx[x] * n + lambda * uo[x], ey = sby[x] * n + lambda * vo[x];
    const float inv_det = 1.f / (a * d - gxy * gxy);
    un[x] = (d * ex - gxy * ey) * inv_det;
    vn[x] = (a * ey - gxy * ex) * inv_det;
  }
}

// One refinement iteration for rows [yb, ye) of the computed rectangle. Reads the previous
// flow (planar, comp-sized), writes the new one. Everything a row needs is produced by
// streaming: warped rows -> derivative-product rows -> vertical running sums -> horizontal
// running sums -> 2x2 solve, so the working set stays a few rows wide.
class RowIterator {
 public:
  RowIterator(const LevelProblem& p, const float* u_old, const float* v_old)
      : p_(p),
        u_old_(u_old),
        v_old_(v_old),
        w_(p.comp.width),
        h_(p.comp.height),
        ring_rows_(p.win.hi - p.win.lo + 2),
        padded_(w_ + 2) {
    for (int i = 0; i < 4; ++i) {
      WarpedRow& e = warp_cache_[i];
      e.row = -1;
      e.m.assign(padded_, 0.f);
      e.d.assign(padded_, 0.f);
      e.u.assign(padded_, 0.f);
      e.v.assign(padded_, 0.f);
    }
    ring_.assign(static_cast<size_t>(ring_rows_) * kChannels * w_, 0.f);
    ring_row_id_.assign(ring_rows_, kNoRow);
    colsum_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
    hpad_lo_ = -p.win.lo;
    const int hpad = hpad_lo_ + w_ + p.win.hi + 1;
    col_.assign(static_cast<size_t>(kChannels) * hpad, 0.f);
    col_stride_ = hpad;
    win_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
    delta_.assign(static_cast<size_t>(w_) + p.win.hi - p.win.lo + 2, 0.f);
    deriv_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
    zero_row_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
  }

  void run(int yb, int ye, float* u_new, float* v_new, float* confidence) {
    const Window& win = p_.win;
    // Prime the vertical sum with the full window of row yb.
    std::fill(colsum_.begin(), colsum_.end(), 0.f);
    for (int s = yb + win.lo; s <= yb + win.hi; ++s)
      add_row(products(s), 1.f);
    for (int y = yb; y < ye; ++y) {
      if (y > yb) {
        add_row(products(y + win.hi), 1.f);
        add_row(products(y + win.lo - 1), -1.f);
      }
      vertical_output(y);
      horizontal_sums();
      solve_row(y, u_new + static_cast<size_t>(y) * w_, v_new + static_cast<size_t>(y) * w_,
                confidence ? confidence + static_cast<size_t>(y) * w_ : nullptr);
    }
  }

 private:
  static constexpr int kNoRow = -1 << 30;

  // Mean image (I0 + warped I1) / 2, difference warped I1 - I0, and flow of row r of comp.
  const WarpedRow& warped(int r) {
    r = std::clamp(r, 0, h_ - 1);
    WarpedRow& e = warp_cache_[static_cast<size_t>(r) & 3u];
    if (e.row == r) return e;
    e.row = r;
    const int gy = p_.comp.y + r;
    warp_row(*p_.i1, p_.i0->ptr<float>(gy) + p_.comp.x, p_.comp.x, gy, w_,
             u_old_ + static_cast<size_t>(r) * w_, v_old_ + static_cast<size_t>(r) * w_,
             e.m.data() + 1, e.d.data() + 1);
    const float* u = u_old_ + static_cast<size_t>(r) * w_;
    const float* v = v_old_ + static_cast<size_t>(r) * w_;
    std::copy(u, u + w_, e.u.data() + 1);
    std::copy(v, v + w_, e.v.data() + 1);
    for (auto* vec : {&e.m, &e.d, &e.u, &e.v}) {
      (*vec)[0] = (*vec)[1];
      (*vec)[w_ + 1] = (*vec)[w_];
    }
    return e;
  }

  // Weighted derivative products of derivative-grid row s (zeros outside the rectangle).
  const float* products(int s) {
    if (s < 0 || s >= h_) return zero_row_.data();
    const int slot = ((s % ring_rows_) + ring_rows_) % ring_rows_;
    float* out = ring_.data() + static_cast<size_t>(slot) * kChannels * w_;
    if (ring_row_id_[slot] == s) return out;
    ring_row_id_[slot] = s;
    float* ix = deriv_.data();
    float* iy = ix + w_;
    float* it = iy + w_;
    float* ub = it + w_;
    float* vb = ub + w_;
    switch (p_.derivative) {
      case Derivative::HornSchunck:
        // The 2x2x2 cube between rows s, s + 1 and columns x, x + 1: derivative grid at +1/2.
        hs_derivatives(warped(s), warped(s + 1 < h_ ? s + 1 : s), w_, ix, iy, it, ub, vb);
        break;
      case Derivative::Scharr:
      case Derivative::Central:
        grid_derivatives(p_.derivative == Derivative::Scharr, warped(s - 1), warped(s),
                         warped(s + 1), w_, ix, iy, it, ub, vb);
        break;
    }
    if (p_.robust_inv_scale2 > 0.f) {
      emit_products<true>(w_, ix, iy, it, ub, vb, p_.robust_inv_scale2, out);
    } else {
      emit_products<false>(w_, ix, iy, it, ub, vb, 0.f, out);
    }
    return out;
  }

  void add_row(const float* row, float sign) {
    const size_t n = static_cast<size_t>(kChannels) * w_;
    float* acc = colsum_.data();
    if (sign > 0.f) {
      for (size_t i = 0; i < n; ++i)
        acc[i] += row[i];
    } else {
      for (size_t i = 0; i < n; ++i)
        acc[i] -= row[i];
    }
  }

  // Column sums of output row y, half-weight end rows removed, into the zero-padded col_.
  void vertical_output(int y) {
    const Window& win = p_.win;
    for (int c = 0; c < kChannels; ++c) {
      const float* src = colsum_.data() + static_cast<size_t>(c) * w_;
      float* dst = col_.data() + static_cast<size_t>(c) * col_stride_ + hpad_lo_;
      if (win.half) {
        const float* top = products(y + win.lo) + static_cast<size_t>(c) * w_;
        const float* bot = products(y + win.hi) + static_cast<size_t>(c) * w_;
        for (int x = 0; x < w_; ++x)
          dst[x] = src[x] - 0.5f * (top[x] + bot[x]);
      } else {
        std::copy(src, src + w_, dst);
      }
    }
  }

  // Window sums along x as differences of a prefix sum: the prefix is the only serial part
  // and runs eight lanes wide; the differences and half-weight corrections vectorise.
  void horizontal_sums() {
    const Window& win = p_.win;
    const int span = win.hi - win.lo;
    const int n = w_ + span + 1;  // padded columns
    float* prefix = delta_.data();
    for (int c = 0; c < kChannels; ++c) {
      // col[k] holds column k - hpad_lo_; the window of x covers col[x .. x + span].
      const float* col = col_.data() + static_cast<size_t>(c) * col_stride_;
      float* out = win_.data() + static_cast<size_t>(c) * w_;
      inclusive_prefix(col, n, prefix + 1);
      prefix[0] = 0.f;
      for (int x = 0; x < w_; ++x)
        out[x] = prefix[x + span + 1] - prefix[x];
      if (win.half) {
        for (int x = 0; x < w_; ++x)
          out[x] -= 0.5f * (col[x] + col[x + span]);
      }
    }
  }

  void solve_row(int y, float* u_new, float* v_new, float* confidence) {
    const float* sxx = win_.data();
    const float* sxy = sxx + w_;
    const float* syy = sxy + w_;
    const float inv_cy = 1.f / p_.cy[y];
    const float* inv_cx = p_.inv_cx.data();
    const int w = w_;
    solve_pixels(w, win_.data(), inv_cx, inv_cy, p_.lambda, u_old_ + static_cast<size_t>(y) * w,
                 v_old_ + static_cast<size_t>(y) * w, u_new, v_new);
    if (confidence) {
      for (int x = 0; x < w; ++x) {
        const float n = inv_cx[x] * inv_cy;
        const float gxx = sxx[x] * n, gxy = sxy[x] * n, gyy = syy[x] * n;
        const float half_diff = 0.5f * (gxx - gyy);
        confidence[x] =
            std::max(0.f, 0.5f * (gxx + gyy) - std::sqrt(half_diff * half_diff + gxy * gxy));
      }
    }
  }

  const LevelProblem& p_;
  const float* u_old_;
  const float* v_old_;
  int w_, h_;
  int ring_rows_;
  int padded_;
  RowScratch& scratch_ = thread_scratch();
  WarpedRow* warp_cache_ = scratch_.warp_cache;
  std::vector<float>& ring_ = scratch_.ring;
  std::vector<int>& ring_row_id_ = scratch_.ring_row_id;
  std::vector<float>& colsum_ = scratch_.colsum;
  std::vector<float>& col_ = scratch_.col;
  int col_stride_ = 0;
  int hpad_lo_ = 0;
  std::vector<float>& win_ = scratch_.win;
  std::vector<float>& delta_ = scratch_.delta;
  std::vector<float>& zero_row_ = scratch_.zero_row;
  std::vector<float>& deriv_ = scratch_.deriv;
};

// Rows per stripe handed to the executor: each stripe re-primes its vertical window, so
// stripes much shorter than the window would waste work.
constexpr int kStripeRows = 32;

void iterate_level(const LevelProblem& p, cv::Mat& u, cv::Mat& v, cv::Mat* confidence,
                   int iterations, const Executor& executor) {
  cv::Mat u_next(u.size(), CV_32F), v_next(v.size(), CV_32F);
  for (int it = 0; it < iterations; ++it) {
    const bool last = it + 1 == iterations;
    float* conf = (last && confidence) ? confidence->ptr<float>() : nullptr;
    const float* uo = u.ptr<float>();
    const float* vo = v.ptr<float>();
    float* un = u_next.ptr<float>();
    float* vn = v_next.ptr<float>();
    const int stripes = (p.comp.height + kStripeRows - 1) / kStripeRows;
    executor.for_range(0, stripes, 1, [&](int sb, int se) {
      RowIterator rows(p, uo, vo);
      rows.run(sb * kStripeRows, std::min(p.comp.height, se * kStripeRows), un, vn, conf);
    });
    std::swap(u, u_next);
    std::swap(v, v_next);
  }
}

// Flow component of the coarser level (origin `src_origin` in its level) resampled onto
// rectangle `dst` of the finer level and doubled. Pixel x of the finer level sits at x / 2 of
// the coarser one, so the bilinear weights are 0, 1/2 or 1; borders replicate.
cv::Mat upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst) {
  auto taps = [](int fine, int origin, int n, int& i0, int& i1, float& f) {
    const int twice = fine - 2 * origin;  // 2 * (fine / 2 - origin)
    const int lo = twice >= 0 ? twice / 2 : -((-twice + 1) / 2);
    f = (twice & 1) ? 0.5f : 0.f;
    i0 = std::clamp(lo, 0, n - 1);
    i1 = std::clamp(lo + 1, 0, n - 1);
  };
  std::vector<int> x0(dst.width), x1(dst.width);
  std::vector<float> fx(dst.width), row(src.cols);
  for (int x = 0; x < dst.width; ++x)
    taps(dst.x + x, src_origin.x, src.cols, x0[x], x1[x], fx[x]);
  cv::Mat out(dst.size(), CV_32F);
  for (int y = 0; y < dst.height; ++y) {
    int y0, y1;
    float fy;
    taps(dst.y + y, src_origin.y, src.rows, y0, y1, fy);
    const float* a = src.ptr<float>(y0);
    const float* b = src.ptr<float>(y1);
    for (int x = 0; x < src.cols; ++x)
      row[x] = 2.f * (a[x] + fy * (b[x] - a[x]));
    float* o = out.ptr<float>(y);
    for (int x = 0; x < dst.width; ++x) {
      o[x] = row[x0[x]] + fx[x] * (row[x1[x]] - row[x0[x]]);
    }
  }
  return out;
}

cv::Rect expand(const cv::Rect& r, int by) {
  return {r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by};
}

void median_filter(cv::Mat& u, cv::Mat& v, int ksize) {
  if (ksize <= 1) return;
  cv::medianBlur(u, u, ksize);
  cv::medianBlur(v, v, ksize);
}

}  // namespace

LkParams LkParams::paper() {
  return LkParams{};
}

// Measured on the 8 Middlebury sequences (mean EPE, see README): from `paper`, 5 levels
// reach the large motions, 8 iterations let the robust weights settle, Cauchy reweighting
// (scale 0.008) discounts occlusions and motion boundaries, and 5x5 medians between levels
// and at the end remove isolated outliers.
LkParams LkParams::accurate() {
  LkParams p;
  p.levels = 5;
  p.iterations = 8;
  p.robust_scale = 0.008;
  p.level_median = 5;
  p.final_median = 5;
  return p;
}

LkParams LkParams::preset(std::string_view name) {
  if (name == "paper") return paper();
  if (name == "accurate") return accurate();
  throw Error("unknown preset '" + std::string(name) + "' (expected paper or accurate)");
}

std::vector<std::string> LkParams::preset_names() {
  return {"paper", "accurate"};
}

void LkParams::validate() const {
  auto fail = [](const std::string& what) { throw Error(what); };
  if (patch < 3 || patch > 31) fail("patch must be in 3..31, got " + std::to_string(patch));
  if (levels < 1 || levels > kMaxLevels) {
    fail("levels must be in 1.." + std::to_string(kMaxLevels) + ", got " + std::to_string(levels));
  }
  if (iterations < 1 || iterations > 50) {
    fail("iterations must be in 1..50, got " + std::to_string(iterations));
  }
  if (!(sigma >= 0.0 && sigma <= 20.0))
    fail("sigma must be in [0, 20], got " + std::to_string(sigma));
  if (!(lambda > 0.0 && lambda <= 1.0)) {
    fail("lambda must be in (0, 1], got " + std::to_string(lambda));
  }
  if (!(robust_scale >= 0.0 && robust_scale <= 1.0)) {
    fail("robust scale must be in [0, 1] (0 = off), got " + std::to_string(robust_scale));
  }
  for (int m : {level_median, final_median}) {
    if (m != 0 && m != 3 && m != 5) {
      fail("median filter size must be 0, 3 or 5, got " + std::to_string(m));
    }
  }
}

const char* to_string(Derivative d) {
  switch (d) {
    case Derivative::HornSchunck:
      return "hs";
    case Derivative::Scharr:
      return "scharr";
    case Derivative::Central:
      return "central";
  }
  return "?";
}

Derivative derivative_from_string(std::string_view name) {
  if (name == "hs" || name == "horn-schunck") return Derivative::HornSchunck;
  if (name == "scharr") return Derivative::Scharr;
  if (name == "central") return Derivative::Central;
  throw Error("unknown derivative '" + std::string(name) + "' (expected hs, scharr or central)");
}

FlowResult dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                      const FlowOptions& options) {
  params.validate();
  if (frame_t.empty() || frame_t1.empty()) throw Error("input frame is empty");
  if (frame_t.size() != frame_t1.size()) {
    throw Error("frames differ in size: " + std::to_string(frame_t.cols) + "x" +
                std::to_string(frame_t.rows) + " vs " + std::to_string(frame_t1.cols) + "x" +
                std::to_string(frame_t1.rows));
  }
  return dense_flow(build_pyramid(frame_t, params.levels, params.sigma),
                    build_pyramid(frame_t1, params.levels, params.sigma), params, options);
}

FlowResult dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                      const FlowOptions& options) {
  params.validate();
  const cv::Size size = pyr_t.size();
  if (size.empty() || pyr_t1.size() != size) throw Error("pyramids are empty or differ in size");
  const int levels = effective_levels(size, params.levels);
  if (pyr_t.num_levels() < levels || pyr_t1.num_levels() < levels) {
    throw Error("pyramid has " + std::to_string(std::min(pyr_t.num_levels(), pyr_t1.num_levels())) +
                " levels, " + std::to_string(levels) + " needed");
  }
  const cv::Rect full(cv::Point(), size);
  const cv::Rect region = options.region.empty() ? full : (options.region & full);
  if (region.empty()) throw Error("flow region lies outside the frame");

  const bool half_grid = params.derivative == Derivative::HornSchunck;
  const Window win = make_window(params.patch, half_grid);
  // Flow at a pixel after one iteration depends on the previous flow within the window plus
  // the derivative stencil: computing on a margin of this many pixels per iteration makes a
  // region's flow equal the whole frame's flow inside the region.
  const int reach = win.reach() + 2;
  const int margin =
      params.iterations * reach + std::max(params.level_median, params.final_median) / 2;

  std::vector<cv::Rect> comp(levels);
  cv::Rect need = region;
  for (int l = 0; l < levels; ++l) {
    const cv::Rect level_rect(cv::Point(), pyr_t.levels[l].size());
    comp[l] = expand(need, margin) & level_rect;
    const cv::Rect& c = comp[l];
    need = cv::Rect(cv::Point(c.x / 2, c.y / 2),
                    cv::Point((c.x + c.width - 1) / 2 + 2, (c.y + c.height - 1) / 2 + 2));
  }

  const SerialExecutor serial;
  const Executor& exec = options.executor ? *options.executor : serial;

  cv::Mat u, v, confidence;
  for (int l = levels - 1; l >= 0; --l) {
    const cv::Rect& c = comp[l];
    if (l == levels - 1) {
      const float scale = 1.f / static_cast<float>(1 << l);
      u = cv::Mat(c.size(), CV_32F, cv::Scalar(options.initial_motion.x * scale));
      v = cv::Mat(c.size(), CV_32F, cv::Scalar(options.initial_motion.y * scale));
    } else {
      u = upsample_flow(u, comp[l + 1].tl(), c);
      v = upsample_flow(v, comp[l + 1].tl(), c);
    }
    LevelProblem p;
    p.i0 = &pyr_t.levels[l];
    p.i1 = &pyr_t1.levels[l];
    p.comp = c;
    p.derivative = params.derivative;
    p.win = win;
    p.lambda = static_cast<float>(params.lambda);
    p.robust_inv_scale2 =
        params.robust_scale > 0
            ? static_cast<float>(1.0 / (params.robust_scale * params.robust_scale))
            : 0.f;
    // Windows are clipped at the computed rectangle; near the image border that is the
    // image border, elsewhere only pixels outside the wanted region are affected.
    p.inv_cx.resize(c.width);
    for (int x = 0; x < c.width; ++x)
      p.inv_cx[x] = 1.f / window_weight(win, x, c.width);
    p.cy.resize(c.height);
    for (int y = 0; y < c.height; ++y)
      p.cy[y] = window_weight(win, y, c.height);
    if (l == 0) confidence = cv::Mat(c.size(), CV_32F);
    iterate_level(p, u, v, l == 0 ? &confidence : nullptr, params.iterations, exec);
    if (l > 0) median_filter(u, v, params.level_median);
  }
  median_filter(u, v, params.final_median);

  const cv::Rect crop(region.tl() - comp[0].tl(), region.size());
  FlowResult result;
  cv::merge(std::vector<cv::Mat>{u(crop), v(crop)}, result.flow);
  result.confidence = confidence(crop).clone();
  result.region = region;
  return result;
}

}  // namespace roiflow::flow
