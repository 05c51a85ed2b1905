#include "flow/dense_lk.hpp"

#include <algorithm>
#ifdef __AVX2__
#include <immintrin.h>
#endif
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/error.hpp"

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
  std::vector<float> m, d;   // padded by one on each side (replicated)
  const float* u = nullptr;  // the row's current flow, not padded
  const float* v = nullptr;
};

// Row buffers of one RowIterator. They live per thread and keep their capacity, so the
// iterations of a level allocate nothing.
struct RowScratch {
  WarpedRow warp_cache[4];
  std::vector<float> ring, colsum, col, prefix;
};

// Scratch number `slot` of this thread: the iterations of a level that advance together as a
// wavefront each need their own.
RowScratch& thread_scratch(int slot) {
  thread_local std::vector<std::unique_ptr<RowScratch>> scratch;
  while (static_cast<int>(scratch.size()) <= slot)
    scratch.push_back(std::make_unique<RowScratch>());
  return *scratch[slot];
}

// Frame t+1 sampled bilinearly at x + flow(x) along one row (border replicated), returned
// as the mean with frame t, m = (I0 + I1w) / 2, and the difference d = I1w - I0.
void warp_row(const cv::Mat& i1, const float* __restrict i0, int x0, int y, int w,
              const float* __restrict u, const float* __restrict v, float* __restrict m,
              float* __restrict d) {
  const float* __restrict base = i1.ptr<float>(0);
  const int step = static_cast<int>(i1.step1());
  const int dx1 = i1.cols > 1 ? 1 : 0, dy1 = i1.rows > 1 ? step : 0;
  const float xhi = static_cast<float>(i1.cols - 1), yhi = static_cast<float>(i1.rows - 1);
  const int ixmax = std::max(0, i1.cols - 2), iymax = std::max(0, i1.rows - 2);
  const float fy0 = static_cast<float>(y);
  int x = 0;
#ifdef __AVX2__
  if (dx1 == 1 && dy1 == step) {
    // Each pixel needs two horizontal pairs (p00, p01) and (p10, p11): gathering them as
    // 64-bit pairs halves the gathered elements, which is what gathers cost on x86.
    const __m256 lane = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 zero = _mm256_setzero_ps(), vxhi = _mm256_set1_ps(xhi);
    const __m256 vyhi = _mm256_set1_ps(yhi), vy = _mm256_set1_ps(fy0), half = _mm256_set1_ps(0.5f);
    const __m256i vixmax = _mm256_set1_epi32(ixmax), viymax = _mm256_set1_epi32(iymax);
    const __m256i vstep = _mm256_set1_epi32(step);
    // Each pixel's 2x2 neighbourhood is two 8-byte loads (rows iy and iy + 1 at ix): plain
    // loads and a transpose, because gathers are slow on many x86 cores.
    alignas(32) int index[8];
    auto quad = [&](int i) {
      const float* p = base + index[i];
      const __m128 top = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
      return _mm_loadh_pi(top, reinterpret_cast<const __m64*>(p + step));
    };
    for (; x + 8 <= w; x += 8) {
      const __m256 xs = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(x0 + x)), lane);
      const __m256 sx =
          _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(xs, _mm256_loadu_ps(u + x)), zero), vxhi);
      const __m256 sy =
          _mm256_min_ps(_mm256_max_ps(_mm256_add_ps(vy, _mm256_loadu_ps(v + x)), zero), vyhi);
      const __m256i ix = _mm256_min_epi32(_mm256_cvttps_epi32(sx), vixmax);
      const __m256i iy = _mm256_min_epi32(_mm256_cvttps_epi32(sy), viymax);
      const __m256 fx = _mm256_sub_ps(sx, _mm256_cvtepi32_ps(ix));
      const __m256 fy = _mm256_sub_ps(sy, _mm256_cvtepi32_ps(iy));
      const __m256i idx = _mm256_add_epi32(_mm256_mullo_epi32(iy, vstep), ix);
      _mm256_store_si256(reinterpret_cast<__m256i*>(index), idx);
      // q_i = (p00, p01, p10, p11) of pixel i; transposed so that each register holds one tap.
      __m128 q0 = quad(0), q1 = quad(1), q2 = quad(2), q3 = quad(3);
      __m128 q4 = quad(4), q5 = quad(5), q6 = quad(6), q7 = quad(7);
      _MM_TRANSPOSE4_PS(q0, q1, q2, q3);
      _MM_TRANSPOSE4_PS(q4, q5, q6, q7);
      const __m256 p00 = _mm256_set_m128(q4, q0), p01 = _mm256_set_m128(q5, q1);
      const __m256 p10 = _mm256_set_m128(q6, q2), p11 = _mm256_set_m128(q7, q3);
      const __m256 top = _mm256_fmadd_ps(fx, _mm256_sub_ps(p01, p00), p00);
      const __m256 bot = _mm256_fmadd_ps(fx, _mm256_sub_ps(p11, p10), p10);
      const __m256 w1 = _mm256_fmadd_ps(fy, _mm256_sub_ps(bot, top), top);
      const __m256 a = _mm256_loadu_ps(i0 + x);
      _mm256_storeu_ps(m + x, _mm256_mul_ps(half, _mm256_add_ps(a, w1)));
      _mm256_storeu_ps(d + x, _mm256_sub_ps(w1, a));
    }
  }
#endif
  for (; x < w; ++x) {
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

// The five window terms of one derivative-grid row are Ix², IxIy, Iy² and Ix·r, Iy·r with
// r = Ix·ū + Iy·v̄ − It, the brightness equation linearised around the local flow (ū, v̄).
// Each kernel below computes them for one row, stores them in the ring slot of the row that
// leaves the vertical window (kLeaving: there is one) and moves the vertical running sums by
// the difference, all in one pass. Ix, Iy come from the mean image m, It from d; row padding
// replicates the edge columns, so x - 1 and x + 1 are always valid. Every pointer is a
// restrict parameter: GCC vectorises only with that guarantee.
struct WindowTerms {
  float wix, wiy, ix, iy, r;
};

template <bool kRobust>
inline WindowTerms window_terms(float ix, float iy, float it, float ub, float vb, float inv_s2) {
  float wgt = 1.f;
  if constexpr (kRobust) wgt = 1.f / (1.f + it * it * inv_s2);
  return {wgt * ix, wgt * iy, ix, iy, ix * ub + iy * vb - it};
}

template <bool kLeaving>
inline void enter(float* __restrict ring, float* __restrict sum, int x, float value) {
  sum[x] += kLeaving ? value - ring[x] : value;
  ring[x] = value;
}

template <bool kLeaving>
inline void enter_all(const WindowTerms& t, int w, int x, float* __restrict ring,
                      float* __restrict acc) {
  enter<kLeaving>(ring, acc, x, t.wix * t.ix);
  enter<kLeaving>(ring + w, acc + w, x, t.wix * t.iy);
  enter<kLeaving>(ring + 2 * w, acc + 2 * w, x, t.wiy * t.iy);
  enter<kLeaving>(ring + 3 * w, acc + 3 * w, x, t.wix * t.r);
  enter<kLeaving>(ring + 4 * w, acc + 4 * w, x, t.wiy * t.r);
}

// Horn–Schunck's 2x2x2 cube between rows a, b and columns x, x + 1 (grid at +1/2).
template <bool kRobust, bool kLeaving>
void hs_window_terms(int w, const float* __restrict m0, const float* __restrict m1,
                     const float* __restrict d0, const float* __restrict d1,
                     const float* __restrict u0, const float* __restrict u1,
                     const float* __restrict v0, const float* __restrict v1, float inv_s2,
                     float* __restrict ring, float* __restrict acc) {
  // The flow rows are not padded: the last column (x + 1 replicated) goes apart.
  auto column = [&](int x, int x1) {
    const float ix = 0.5f * ((m0[x + 1] - m0[x]) + (m1[x + 1] - m1[x]));
    const float iy = 0.5f * ((m1[x] - m0[x]) + (m1[x + 1] - m0[x + 1]));
    const float it = 0.25f * (d0[x] + d0[x + 1] + d1[x] + d1[x + 1]);
    const float ub = 0.25f * (u0[x] + u0[x1] + u1[x] + u1[x1]);
    const float vb = 0.25f * (v0[x] + v0[x1] + v1[x] + v1[x1]);
    enter_all<kLeaving>(window_terms<kRobust>(ix, iy, it, ub, vb, inv_s2), w, x, ring, acc);
  };
  // The five channel rows of `ring` and `acc` are disjoint (w apart): no dependence.
#pragma GCC ivdep
  for (int x = 0; x < w - 1; ++x)
    column(x, x + 1);
  column(w - 1, w - 1);
}

// 3x3 Scharr (kScharr) or central differences on the pixel grid, rows up / centre / down.
template <bool kScharr, bool kRobust, bool kLeaving>
void grid_window_terms(int w, const float* __restrict mu, const float* __restrict mc,
                       const float* __restrict md, const float* __restrict dc,
                       const float* __restrict uc, const float* __restrict vc, float inv_s2,
                       float* __restrict ring, float* __restrict acc) {
  // The five channel rows of `ring` and `acc` are disjoint (w apart): no dependence.
#pragma GCC ivdep
  for (int x = 0; x < w; ++x) {
    float ix, iy;
    if constexpr (kScharr) {
      constexpr float k = 1.f / 32.f;
      ix = k * (3.f * (mu[x + 1] - mu[x - 1]) + 10.f * (mc[x + 1] - mc[x - 1]) +
                3.f * (md[x + 1] - md[x - 1]));
      iy = k *
           (3.f * (md[x - 1] - mu[x - 1]) + 10.f * (md[x] - mu[x]) + 3.f * (md[x + 1] - mu[x + 1]));
    } else {
      ix = 0.5f * (mc[x + 1] - mc[x - 1]);
      iy = 0.5f * (md[x] - mu[x]);
    }
    enter_all<kLeaving>(window_terms<kRobust>(ix, iy, dc[x], uc[x], vc[x], inv_s2), w, x, ring,
                        acc);
  }
}

template <bool kRobust, bool kLeaving>
void row_window_terms(Derivative derivative, const WarpedRow& up, const WarpedRow& centre,
                      const WarpedRow& down, int w, float inv_s2, float* ring, float* acc) {
  auto at = [](const std::vector<float>& v) { return v.data() + 1; };
  switch (derivative) {
    case Derivative::HornSchunck:
      // The cube spans this row and the next: `centre` and `down`.
      hs_window_terms<kRobust, kLeaving>(w, at(centre.m), at(down.m), at(centre.d), at(down.d),
                                         centre.u, down.u, centre.v, down.v, inv_s2, ring, acc);
      break;
    case Derivative::Scharr:
      grid_window_terms<true, kRobust, kLeaving>(w, at(up.m), at(centre.m), at(down.m),
                                                 at(centre.d), centre.u, centre.v, inv_s2, ring,
                                                 acc);
      break;
    case Derivative::Central:
      grid_window_terms<false, kRobust, kLeaving>(w, at(up.m), at(centre.m), at(down.m),
                                                  at(centre.d), centre.u, centre.v, inv_s2, ring,
                                                  acc);
      break;
  }
}

// Inclusive prefix sums of the kChannels rows in[c * in_stride + i], i < n, into
// out[c * out_stride + i]. The channels' carry chains are independent, so interleaving them
// hides the latency of the serial part.
void prefix_scan(const float* __restrict in, int in_stride, int n, float* __restrict out,
                 size_t out_stride) {
  int i = 0;
  float carry[kChannels] = {};
#ifdef __AVX2__
  __m256 vcarry[kChannels];
  for (int c = 0; c < kChannels; ++c)
    vcarry[c] = _mm256_setzero_ps();
  for (; i + 8 <= n; i += 8) {
    for (int c = 0; c < kChannels; ++c) {
      __m256 x = _mm256_loadu_ps(in + static_cast<size_t>(c) * in_stride + i);
      x = _mm256_add_ps(x, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(x), 4)));
      x = _mm256_add_ps(x, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(x), 8)));
      // Each 128-bit half now holds its own prefix; carry the low half's total into the high.
      const __m256 low_total = _mm256_permute_ps(x, _MM_SHUFFLE(3, 3, 3, 3));
      x = _mm256_add_ps(x, _mm256_permute2f128_ps(low_total, low_total, 0x08));
      x = _mm256_add_ps(x, vcarry[c]);
      _mm256_storeu_ps(out + c * out_stride + i, x);
      const __m256 last = _mm256_permute_ps(x, _MM_SHUFFLE(3, 3, 3, 3));
      vcarry[c] = _mm256_permute2f128_ps(last, last, 0x11);
    }
  }
  for (int c = 0; c < kChannels; ++c)
    carry[c] = _mm256_cvtss_f32(vcarry[c]);
#endif
  for (; i < n; ++i) {
    for (int c = 0; c < kChannels; ++c) {
      carry[c] += in[static_cast<size_t>(c) * in_stride + i];
      out[c * out_stride + i] = carry[c];
    }
  }
}

// Everything the per-row solve needs: prefix sums (padded, see RowIterator) from which each
// window sum is one difference, the half-weight end columns when the window has them, and
// the window weights.
struct WindowSolve {
  int w;
  const float* prefix;
  size_t prefix_stride;
  const float* columns;  // non-null: subtract half of the end columns (zero-padded)
  int column_stride;
  int lo, hi;
  const float* inv_cx;
  float inv_cy;
  float lambda;
};

// The regularised 2x2 solve of one row: (G + lambda I) w = b + lambda w_old, with G and b
// the window means; optionally the smallest eigenvalue of G as the confidence.
template <bool kHalf, bool kConfidence>
void solve_row_impl(const WindowSolve& ws, const float* __restrict uo, const float* __restrict vo,
                    float* __restrict un, float* __restrict vn, float* __restrict confidence) {
  const size_t ps = ws.prefix_stride;
  const float* __restrict p0 = ws.prefix;
  const float* __restrict p1 = p0 + ps;
  const float* __restrict p2 = p1 + ps;
  const float* __restrict p3 = p2 + ps;
  const float* __restrict p4 = p3 + ps;
  const size_t cs = static_cast<size_t>(ws.column_stride);
  const float* __restrict c0 = ws.columns;
  const float* __restrict c1 = kHalf ? c0 + cs : nullptr;
  const float* __restrict c2 = kHalf ? c1 + cs : nullptr;
  const float* __restrict c3 = kHalf ? c2 + cs : nullptr;
  const float* __restrict c4 = kHalf ? c3 + cs : nullptr;
  const int lo = ws.lo - 1, hi = ws.hi, elo = ws.lo;
  const float* __restrict inv_cx = ws.inv_cx;
  const float inv_cy = ws.inv_cy, lambda = ws.lambda;
  for (int x = 0; x < ws.w; ++x) {
    float sxx = p0[x + hi] - p0[x + lo], sxy = p1[x + hi] - p1[x + lo];
    float syy = p2[x + hi] - p2[x + lo], sbx = p3[x + hi] - p3[x + lo];
    float sby = p4[x + hi] - p4[x + lo];
    if constexpr (kHalf) {
      sxx -= 0.5f * (c0[x + elo] + c0[x + hi]);
      sxy -= 0.5f * (c1[x + elo] + c1[x + hi]);
      syy -= 0.5f * (c2[x + elo] + c2[x + hi]);
      sbx -= 0.5f * (c3[x + elo] + c3[x + hi]);
      sby -= 0.5f * (c4[x + elo] + c4[x + hi]);
    }
    const float n = inv_cx[x] * inv_cy;
    const float gxx = sxx * n, gxy = sxy * n, gyy = syy * n;
    const float a = gxx + lambda, d = gyy + lambda;
    const float ex = sbx * n + lambda * uo[x], ey = sby * n + lambda * vo[x];
    const float inv_det = 1.f / (a * d - gxy * gxy);
    un[x] = (d * ex - gxy * ey) * inv_det;
    vn[x] = (a * ey - gxy * ex) * inv_det;
    if constexpr (kConfidence) {
      const float half_diff = 0.5f * (gxx - gyy);
      confidence[x] =
          std::max(0.f, 0.5f * (gxx + gyy) - std::sqrt(half_diff * half_diff + gxy * gxy));
    }
  }
}

void solve_pixels(const WindowSolve& ws, const float* uo, const float* vo, float* un, float* vn,
                  float* confidence) {
  if (ws.columns) {
    if (confidence) return solve_row_impl<true, true>(ws, uo, vo, un, vn, confidence);
    return solve_row_impl<true, false>(ws, uo, vo, un, vn, confidence);
  }
  if (confidence) return solve_row_impl<false, true>(ws, uo, vo, un, vn, confidence);
  solve_row_impl<false, false>(ws, uo, vo, un, vn, confidence);
}

// Rows per stripe handed to the executor; the vertical window sums restart at each stripe
// boundary, so stripes much shorter than the window would waste work.
constexpr int kStripeRows = 32;

// One refinement iteration for rows [yb, ye) of the computed rectangle. Reads the previous
// flow (planar, comp-sized), writes the new one. Everything a row needs is produced by
// streaming: warped rows -> derivative-product rows -> vertical running sums -> horizontal
// running sums -> 2x2 solve, so the working set stays a few rows wide.
class RowIterator {
 public:
  RowIterator(const LevelProblem& p, const float* u_old, const float* v_old, int scratch_slot)
      : p_(p),
        u_old_(u_old),
        v_old_(v_old),
        w_(p.comp.width),
        h_(p.comp.height),
        ring_rows_(p.win.hi - p.win.lo + 1),
        scratch_(thread_scratch(scratch_slot)) {
    for (int i = 0; i < 4; ++i) {
      WarpedRow& e = warp_cache_[i];
      e.row = -1;
      e.m.resize(w_ + 2);  // one replicated column on each side
      e.d.resize(w_ + 2);
    }
    // Rows of these buffers are always written before they are read: no clearing needed.
    ring_.resize(static_cast<size_t>(ring_rows_) * kChannels * w_);
    colsum_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
    hpad_lo_ = -p.win.lo;
    const int hpad = hpad_lo_ + w_ + p.win.hi + 1;
    col_.assign(static_cast<size_t>(kChannels) * hpad, 0.f);
    col_stride_ = hpad;
    // Prefix sums per channel: 1 - lo zeros before column 0 and hi copies of the total after
    // the last, so every window is prefix[x + hi] - prefix[x + lo - 1] without a clamp.
    prefix_pad_ = 1 - p.win.lo;
    prefix_stride_ = static_cast<size_t>(prefix_pad_ + w_ + p.win.hi);
    prefix_.assign(kChannels * prefix_stride_, 0.f);
  }

  // Rows [yb, ye) of the new flow. yb must be a multiple of kStripeRows (or 0).
  void run(int yb, int ye, float* u_new, float* v_new, float* confidence) {
    start(yb);
    for (int y = yb; y < ye; ++y)
      next_row(u_new, v_new, confidence);
  }

  // Row by row: start(yb), then each next_row() writes the next row of the new flow. Row y
  // reads rows y .. y + lookahead() of the previous flow.
  void start(int yb) {
    for (int s = yb + p_.win.lo; s < yb + p_.win.hi; ++s)
      advance(s, false);
    first_ = next_ = yb;
  }
  int lookahead() const { return p_.win.hi + 1; }

  void next_row(float* u_new, float* v_new, float* confidence) {
    const Window& win = p_.win;
    const int y = next_++;
    advance(y + win.hi, y > first_);
    // A running sum's rounding depends on where it started. Summing the window afresh at
    // every stripe boundary makes the result independent of how rows are split among
    // threads: bit-identical for any thread count.
    if (y % kStripeRows == 0) resum_window(y);
    const float* columns = colsum_.data();
    int stride = w_;
    if (win.half) {
      half_weight_ends(y);
      columns = col_.data() + hpad_lo_;
      stride = col_stride_;
    }
    const size_t pstride = prefix_stride_;
    float* prefix = prefix_.data() + prefix_pad_;
    prefix_scan(columns, stride, w_, prefix, pstride);
    for (int c = 0; c < kChannels; ++c) {
      float* pc = prefix + c * pstride;
      std::fill(pc + w_, pc + w_ + win.hi, pc[w_ - 1]);
    }
    const size_t off = static_cast<size_t>(y) * w_;
    WindowSolve ws{w_,
                   prefix,
                   pstride,
                   win.half ? columns : nullptr,
                   stride,
                   win.lo,
                   win.hi,
                   p_.inv_cx.data(),
                   1.f / p_.cy[y],
                   p_.lambda};
    solve_pixels(ws, u_old_ + off, v_old_ + off, u_new + off, v_new + off,
                 confidence ? confidence + off : nullptr);
  }

 private:
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
    e.u = u_old_ + static_cast<size_t>(r) * w_;
    e.v = v_old_ + static_cast<size_t>(r) * w_;
    for (auto* vec : {&e.m, &e.d}) {
      (*vec)[0] = (*vec)[1];
      (*vec)[w_ + 1] = (*vec)[w_];
    }
    return e;
  }

  void resum_window(int y) {
    std::fill(colsum_.begin(), colsum_.end(), 0.f);
    const size_t n = static_cast<size_t>(kChannels) * w_;
    float* __restrict acc = colsum_.data();
    for (int s = y + p_.win.lo; s <= y + p_.win.hi; ++s) {
      const float* __restrict row = ring_row(s);
      for (size_t i = 0; i < n; ++i)
        acc[i] += row[i];
    }
  }

  // The ring holds the products of the derivative-grid rows in the vertical window.
  float* ring_row(int s) {
    const int slot = ((s % ring_rows_) + ring_rows_) % ring_rows_;
    return ring_.data() + static_cast<size_t>(slot) * kChannels * w_;
  }

  // Brings derivative-grid row s (zero outside the rectangle) into the vertical window;
  // with `leaving`, row s - ring_rows_ leaves it.
  void advance(int s, bool leaving) {
    float* row = ring_row(s);
    float* acc = colsum_.data();
    const float inv_s2 = p_.robust_inv_scale2;
    if (s < 0 || s >= h_) {
      const size_t n = static_cast<size_t>(kChannels) * w_;
      for (size_t i = 0; i < n; ++i) {
        if (leaving) acc[i] -= row[i];
        row[i] = 0.f;
      }
      return;
    }
    // Horn–Schunck reads rows s, s + 1; the grid stencils s - 1, s, s + 1 (clamped).
    const WarpedRow& up = warped(p_.derivative == Derivative::HornSchunck ? s : s - 1);
    const WarpedRow& centre = warped(s);
    const WarpedRow& down = warped(s + 1);
    if (inv_s2 > 0.f) {
      if (leaving) {
        row_window_terms<true, true>(p_.derivative, up, centre, down, w_, inv_s2, row, acc);
      } else {
        row_window_terms<true, false>(p_.derivative, up, centre, down, w_, inv_s2, row, acc);
      }
    } else if (leaving) {
      row_window_terms<false, true>(p_.derivative, up, centre, down, w_, inv_s2, row, acc);
    } else {
      row_window_terms<false, false>(p_.derivative, up, centre, down, w_, inv_s2, row, acc);
    }
  }

  // Column sums of output row y with the two end rows at weight 1/2, into the zero-padded
  // col_ (the padding gives the horizontal half-weight correction its zeros off the edge).
  void half_weight_ends(int y) {
    const Window& win = p_.win;
    const float* top = ring_row(y + win.lo);
    const float* bot = ring_row(y + win.hi);
    for (int c = 0; c < kChannels; ++c) {
      const size_t o = static_cast<size_t>(c) * w_;
      const float* __restrict src = colsum_.data() + o;
      const float* __restrict t = top + o;
      const float* __restrict b = bot + o;
      float* __restrict dst = col_.data() + static_cast<size_t>(c) * col_stride_ + hpad_lo_;
      for (int x = 0; x < w_; ++x)
        dst[x] = src[x] - 0.5f * (t[x] + b[x]);
    }
  }

  const LevelProblem& p_;
  const float* u_old_;
  const float* v_old_;
  int w_, h_;
  int ring_rows_;
  RowScratch& scratch_;
  int first_ = 0, next_ = 0;
  WarpedRow* warp_cache_ = scratch_.warp_cache;
  std::vector<float>& ring_ = scratch_.ring;
  std::vector<float>& colsum_ = scratch_.colsum;
  std::vector<float>& col_ = scratch_.col;
  int col_stride_ = 0;
  int hpad_lo_ = 0;
  std::vector<float>& prefix_ = scratch_.prefix;
  size_t prefix_stride_ = 0;
  int prefix_pad_ = 0;
};

void iterate_level(const LevelProblem& p, cv::Mat& u, cv::Mat& v, cv::Mat& u_next, cv::Mat& v_next,
                   cv::Mat* confidence, int iterations, const Executor& executor) {
  u_next.create(u.size(), CV_32F);
  v_next.create(v.size(), CV_32F);
  const int h = p.comp.height;
  // Iteration k reads the flow of iteration k - 1 (ping-pong between the two buffers) and
  // writes its own; the last one also the confidence.
  auto input = [&](int k, int plane) -> cv::Mat& {
    return (k % 2 == 0) ? (plane == 0 ? u : v) : (plane == 0 ? u_next : v_next);
  };
  auto output = [&](int k, int plane) -> cv::Mat& { return input(k + 1, plane); };
  auto conf_of = [&](int k) {
    return (k + 1 == iterations && confidence) ? confidence->ptr<float>() : nullptr;
  };
  // Stripes pay only when every thread gets a few of them: each costs a task, a fresh window
  // sum and a pass over the level per iteration instead of the wavefront's one. A tracker's
  // region of ~100 rows split over two threads (one of them busy decoding) ran slower than the
  // serial schedule.
  const int stripes = (h + kStripeRows - 1) / kStripeRows;
  if (executor.concurrency() == 1 || stripes < 2 * executor.concurrency()) {
    // Serial: all iterations advance together as a wavefront, iteration k a fixed lag
    // behind k - 1, so each row is read again while it is still in cache instead of once per
    // pass over the level. Iteration k + 1 overwrites a row of k - 1's buffer only after
    // iteration k, the last reader of that row, has moved past it.
    std::vector<RowIterator> rows;
    rows.reserve(iterations);
    for (int k = 0; k < iterations; ++k) {
      rows.emplace_back(p, input(k, 0).ptr<float>(), input(k, 1).ptr<float>(), k);
    }
    const int lag = rows[0].lookahead() + 1;
    for (int t = 0; t < h + (iterations - 1) * lag; ++t) {
      for (int k = 0; k < iterations; ++k) {
        const int y = t - k * lag;
        if (y == 0) rows[k].start(0);  // reads rows 0 .. lookahead() - 1 of its input
        if (y >= 0 && y < h) {
          rows[k].next_row(output(k, 0).ptr<float>(), output(k, 1).ptr<float>(), conf_of(k));
        }
      }
    }
  } else {
    for (int k = 0; k < iterations; ++k) {
      const float* uo = input(k, 0).ptr<float>();
      const float* vo = input(k, 1).ptr<float>();
      float* un = output(k, 0).ptr<float>();
      float* vn = output(k, 1).ptr<float>();
      float* conf = conf_of(k);
      executor.for_range(0, stripes, 1, [&](int sb, int se) {
        RowIterator stripe(p, uo, vo, 0);
        stripe.run(sb * kStripeRows, std::min(h, se * kStripeRows), un, vn, conf);
      });
    }
  }
  if (iterations % 2 == 1) {
    std::swap(u, u_next);
    std::swap(v, v_next);
  }
}

// Flow component of the coarser level (origin `src_origin` in its level) resampled onto
// rectangle `dst` of the finer level and doubled. Pixel x of the finer level sits at x / 2 of
// the coarser one, so along each axis the finer pixels alternate between copies of a coarse
// pixel and means of two neighbours; borders replicate.
void upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst, cv::Mat& out) {
  const int n = src.cols;
  // Coarse index of finer pixel 0 (floor of half of `twice`) and whether it falls between
  // two coarse pixels. dst lies inside the coarse rectangle, so the index is >= 0.
  const int twice_x = dst.x - 2 * src_origin.x;
  const int k0 = twice_x >> 1;
  const bool x_between = (twice_x & 1) != 0;
  std::vector<float> copy(n + 2), mean(n + 2);
  out.create(dst.size(), CV_32F);
  for (int y = 0; y < dst.height; ++y) {
    const int twice_y = dst.y + y - 2 * src_origin.y;
    const int y0 = std::clamp(twice_y >> 1, 0, src.rows - 1);
    const int y1 = std::min(y0 + 1, src.rows - 1);
    const float fy = (twice_y & 1) ? 0.5f : 0.f;
    const float* a = src.ptr<float>(y0);
    const float* b = src.ptr<float>(y1);
    for (int x = 0; x < n; ++x)
      copy[x] = 2.f * (a[x] + fy * (b[x] - a[x]));
    copy[n] = copy[n + 1] = copy[n - 1];
    for (int x = 0; x <= n; ++x)
      mean[x] = 0.5f * (copy[x] + copy[x + 1]);
    // Finer pixels alternate: even ones take `first`, odd ones `second`.
    const float* first = x_between ? mean.data() + k0 : copy.data() + k0;
    const float* second = x_between ? copy.data() + k0 + 1 : mean.data() + k0;
    float* o = out.ptr<float>(y);
    const int pairs = dst.width / 2;
    for (int i = 0; i < pairs; ++i) {
      o[2 * i] = first[i];
      o[2 * i + 1] = second[i];
    }
    if (dst.width & 1) o[dst.width - 1] = first[pairs];
  }
}

// Buffers of dense_flow kept per thread across calls: allocating them afresh (about 10 MB
// for a VGA pair) costs page faults on every call. A nested call on the same thread (a TBB
// worker that picks up another pair while it waits) gets a private workspace instead.
struct Workspace {
  bool busy = false;
  Pyramid pyr_t, pyr_t1;
  std::vector<cv::Mat> u, v, u_next, v_next;  // per level
  cv::Mat confidence;                         // level 0, when only a region is returned
};

class WorkspaceLease {
 public:
  WorkspaceLease() {
    thread_local Workspace shared;
    if (shared.busy) {
      own_ = std::make_unique<Workspace>();
      ws_ = own_.get();
    } else {
      ws_ = &shared;
    }
    ws_->busy = true;
  }
  ~WorkspaceLease() { ws_->busy = false; }
  WorkspaceLease(const WorkspaceLease&) = delete;
  WorkspaceLease& operator=(const WorkspaceLease&) = delete;
  Workspace& operator*() const { return *ws_; }

 private:
  std::unique_ptr<Workspace> own_;
  Workspace* ws_ = nullptr;
};

cv::Rect expand(const cv::Rect& r, int by) {
  return {r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by};
}

void median_filter(cv::Mat& u, cv::Mat& v, int ksize) {
  if (ksize <= 1) return;
  cv::medianBlur(u, u, ksize);
  cv::medianBlur(v, v, ksize);
}

// Which levels LK runs on and the rectangle each level computes (coarsest last).
struct LevelPlan {
  int finest = 0;  // LK runs on levels finest .. top - 1
  int top = 1;
  // Levels >= finest: the finer level's rectangle halved (the region itself at the finest
  // level, in its pixels), plus the margin the iterations read, clipped to the level. Levels
  // below finest: where the finest level's flow is upsampled to, down to the region at level 0.
  std::vector<cv::Rect> comp;
};

LevelPlan plan_levels(cv::Size size, const LkParams& params, const FlowOptions& options,
                      const cv::Rect& region) {
  if (options.context < -1 || options.context > 1000) {
    throw Error("flow context must be in -1..1000 pixels, got " + std::to_string(options.context));
  }
  if (options.finest_level < 0 || options.finest_level >= kMaxLevels) {
    throw Error("flow finest level must be in 0.." + std::to_string(kMaxLevels - 1) + ", got " +
                std::to_string(options.finest_level));
  }
  LevelPlan plan;
  plan.top = flow_pyramid_levels(size, params, options);
  plan.finest = std::min(options.finest_level, plan.top - 1);
  const Window win = make_window(params.patch, params.derivative == Derivative::HornSchunck);
  // Flow at a pixel after one iteration depends on the previous flow within the window plus
  // the derivative stencil: computing on a margin of this many pixels per iteration makes a
  // region's flow equal the whole frame's flow inside the region (up to rounding).
  const int reach = win.reach() + 2;
  const int margin =
      options.context >= 0
          ? options.context
          : params.iterations * reach + std::max(params.level_median, params.final_median) / 2;
  plan.comp.resize(plan.top);
  cv::Rect need = region;
  for (int l = 0; l < plan.top; ++l) {
    const cv::Rect level(cv::Point(), level_size(size, l));
    plan.comp[l] = (l < plan.finest ? need : expand(need, margin)) & level;
    const cv::Rect& c = plan.comp[l];
    need = cv::Rect(cv::Point(c.x / 2, c.y / 2),
                    cv::Point((c.x + c.width - 1) / 2 + 2, (c.y + c.height - 1) / 2 + 2));
  }
  return plan;
}

// `src` (the finest level's confidence over rectangle `from` of level `level`) sampled at the
// nearest level pixel for every level-0 pixel of `region`.
void confidence_to_level0(const cv::Mat& src, const cv::Rect& from, int level,
                          const cv::Rect& region, cv::Mat& out) {
  out.create(region.size(), CV_32F);
  const int half = level > 0 ? 1 << (level - 1) : 0;
  std::vector<int> column(region.width);
  for (int x = 0; x < region.width; ++x)
    column[x] = std::clamp(((region.x + x + half) >> level) - from.x, 0, src.cols - 1);
  for (int y = 0; y < region.height; ++y) {
    const int sy = std::clamp(((region.y + y + half) >> level) - from.y, 0, src.rows - 1);
    const float* in = src.ptr<float>(sy);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < region.width; ++x)
      o[x] = in[column[x]];
  }
}

// Dense flow from pyramids with `ws`'s buffers (params already validated).
void flow_from_pyramids(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                        FlowResult& result, const FlowOptions& options, Workspace& ws) {
  const cv::Size size = pyr_t.size();
  if (size.empty() || pyr_t1.size() != size) throw Error("pyramids are empty or differ in size");
  const cv::Rect full(cv::Point(), size);
  const cv::Rect region = options.region.empty() ? full : (options.region & full);
  if (region.empty()) throw Error("flow region lies outside the frame");
  const LevelPlan plan = plan_levels(size, params, options, region);
  const int levels = plan.top;
  if (pyr_t.num_levels() < levels || pyr_t1.num_levels() < levels) {
    throw Error("pyramid has " + std::to_string(std::min(pyr_t.num_levels(), pyr_t1.num_levels())) +
                " levels, " + std::to_string(levels) + " needed");
  }

  const bool half_grid = params.derivative == Derivative::HornSchunck;
  const Window win = make_window(params.patch, half_grid);
  const std::vector<cv::Rect>& comp = plan.comp;

  const SerialExecutor serial;
  const Executor& exec = options.executor ? *options.executor : serial;

  for (auto* mats : {&ws.u, &ws.v, &ws.u_next, &ws.v_next})
    mats->resize(levels);
  // The finest level computes the confidence straight into the result when it is level 0 and
  // the region is all of it.
  const cv::Rect crop(region.tl() - comp[0].tl(), region.size());
  const bool direct = plan.finest == 0 && crop.size() == comp[0].size();
  cv::Mat& confidence = direct ? result.confidence : ws.confidence;
  for (int l = levels - 1; l >= 0; --l) {
    const cv::Rect& c = comp[l];
    cv::Mat& u = ws.u[l];
    cv::Mat& v = ws.v[l];
    if (l == levels - 1) {
      const float scale = 1.f / static_cast<float>(1 << l);
      u.create(c.size(), CV_32F);
      v.create(c.size(), CV_32F);
      u.setTo(options.initial_motion.x * scale);
      v.setTo(options.initial_motion.y * scale);
    } else {
      upsample_flow(ws.u[l + 1], comp[l + 1].tl(), c, u);
      upsample_flow(ws.v[l + 1], comp[l + 1].tl(), c, v);
    }
    if (l < plan.finest) continue;  // below the finest level the flow is only upsampled
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
    const bool finest = l == plan.finest;
    if (finest) confidence.create(c.size(), CV_32F);
    iterate_level(p, u, v, ws.u_next[l], ws.v_next[l], finest ? &confidence : nullptr,
                  params.iterations, exec);
    median_filter(u, v, finest ? params.final_median : params.level_median);
  }

  const cv::Mat planes[] = {ws.u[0](crop), ws.v[0](crop)};
  result.flow.create(crop.size(), CV_32FC2);
  cv::merge(planes, 2, result.flow);
  if (plan.finest > 0) {
    confidence_to_level0(confidence, comp[plan.finest], plan.finest, region, result.confidence);
  } else if (!direct) {
    confidence(crop).copyTo(result.confidence);
  }
  result.region = region;
}

}  // namespace

cv::Rect flow_footprint(cv::Size size, const LkParams& params, const FlowOptions& options) {
  params.validate();
  const cv::Rect full(cv::Point(), size);
  const cv::Rect region = options.region.empty() ? full : (options.region & full);
  if (region.empty()) throw Error("flow region lies outside the frame");
  cv::Rect out = region;
  const LevelPlan plan = plan_levels(size, params, options, region);
  for (int l = plan.finest; l < plan.top; ++l) {
    const int f = 1 << l;
    const cv::Rect& c = plan.comp[l];
    out |= cv::Rect(c.x * f, c.y * f, c.width * f, c.height * f);
  }
  return out & full;
}

int flow_pyramid_levels(cv::Size size, const LkParams& params, const FlowOptions& options) {
  const int finest = std::clamp(options.finest_level, 0, kMaxLevels - 1);
  const int top = std::max(params.levels, finest + std::min(params.levels, 2));
  return effective_levels(size, std::min(kMaxLevels, top));
}

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

void dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options) {
  params.validate();
  if (frame_t.empty() || frame_t1.empty()) throw Error("input frame is empty");
  if (frame_t.size() != frame_t1.size()) {
    throw Error("frames differ in size: " + std::to_string(frame_t.cols) + "x" +
                std::to_string(frame_t.rows) + " vs " + std::to_string(frame_t1.cols) + "x" +
                std::to_string(frame_t1.rows));
  }
  WorkspaceLease lease;
  Workspace& ws = *lease;
  const int levels = flow_pyramid_levels(frame_t.size(), params, options);
  build_pyramid(frame_t, levels, params.sigma, ws.pyr_t);
  build_pyramid(frame_t1, levels, params.sigma, ws.pyr_t1);
  flow_from_pyramids(ws.pyr_t, ws.pyr_t1, params, result, options, ws);
}

void dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options) {
  params.validate();
  WorkspaceLease lease;
  flow_from_pyramids(pyr_t, pyr_t1, params, result, options, *lease);
}

FlowResult dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                      const FlowOptions& options) {
  FlowResult result;
  dense_flow(frame_t, frame_t1, params, result, options);
  return result;
}

FlowResult dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                      const FlowOptions& options) {
  FlowResult result;
  dense_flow(pyr_t, pyr_t1, params, result, options);
  return result;
}

}  // namespace roiflow::flow
