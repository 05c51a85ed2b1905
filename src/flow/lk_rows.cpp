#include "flow/lk_rows.hpp"

#include <algorithm>
#ifdef __AVX2__
#include <immintrin.h>
#endif
#include <cmath>

namespace roiflow::flow::detail {

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

namespace {

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
void row_window_terms_t(Derivative derivative, const WarpedRow& up, const WarpedRow& centre,
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

}  // namespace

void row_window_terms(Derivative derivative, const WarpedRow& up, const WarpedRow& centre,
                      const WarpedRow& down, int w, float inv_s2, bool leaving, float* ring,
                      float* acc) {
  if (inv_s2 > 0.f) {
    if (leaving)
      return row_window_terms_t<true, true>(derivative, up, centre, down, w, inv_s2, ring, acc);
    return row_window_terms_t<true, false>(derivative, up, centre, down, w, inv_s2, ring, acc);
  }
  if (leaving)
    return row_window_terms_t<false, true>(derivative, up, centre, down, w, inv_s2, ring, acc);
  row_window_terms_t<false, false>(derivative, up, centre, down, w, inv_s2, ring, acc);
}

// Inclusive prefix sums of the kChannels rows in[c * in_stride + i], i < n, into
// out[c * out_stride + i]. The channels' carry chains are independent, so interleaving them
// hides the latency of the serial part.
void prefix_scan(const float* __restrict in, int in_stride, int n, float* __restrict out,
                 std::size_t out_stride) {
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

namespace {

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

}  // namespace

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

}  // namespace roiflow::flow::detail
