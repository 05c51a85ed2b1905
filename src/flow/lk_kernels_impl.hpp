// The row kernels of dense LK (warp, window terms and sums, prefix sums, 2x2 solve; the
// Horn–Schunck pairs are in lk_pairs_impl.hpp), written once against simd.hpp; lk_band_impl.hpp
// drives them over the rows of a level. Included by lk_band_impl.hpp only, once per instruction
// set: everything here has internal linkage, and no standard-library template is used, so the
// copies built with different instruction sets share no symbol.
#include <cstddef>
#include <cstdint>
#include <cstring>

#pragma once

#include "flow/lk_kernels.hpp"
#include "flow/lk_window_impl.hpp"
#include "flow/simd.hpp"

namespace roiflow::flow::detail {
namespace {

using simd::Native;
using simd::Scalar;
using Idx = std::ptrdiff_t;

constexpr int kChannels = 5;  // gxx, gxy, gyy, bx, by
constexpr int kFactors = 4;   // what a ring row keeps per pixel: Ix, Iy, r, robust weight
constexpr int kPad = 16;      // floats before and after each warped row (64 bytes)

int imin(int a, int b) {
  return a < b ? a : b;
}
int imax(int a, int b) {
  return a < b ? b : a;
}
int floor_to(int v, int step) {
  return v >= 0 ? v / step * step : -((-v + step - 1) / step) * step;
}
Idx round_up(Idx v, Idx step) {
  return (v + step - 1) / step * step;
}

float* row_u(const FlowRows& f, int r) {
  return f.u + ((r - f.first) & f.mask) * f.stride;
}
float* row_v(const FlowRows& f, int r) {
  return f.v + ((r - f.first) & f.mask) * f.stride;
}

// ---------------------------------------------------------------------------------------------
// Warp: frame t+1 sampled bilinearly at x + flow(x) (border replicated); m = (I0 + I1w) / 2,
// d = I1w - I0.

struct WarpGeometry {
  const float* base;
  Idx step;
  float xhi, yhi;
  int ixmax, iymax;
  int dx1, dy1;  // offsets of the right and lower neighbours (0 on a one-pixel side)
};

// The four taps of a vector whose samples lie in one row or two adjacent ones, less than 31
// columns apart, by two loads of 32 columns per row, permutes and, over two rows, a per-lane
// choice (a gather loads lane by lane): false where they do not, or without two-vector permutes.
template <class S>
ROIFLOW_INLINE bool near_taps(const WarpGeometry& g, typename S::I ix, typename S::I iy,
                              typename S::F& p00, typename S::F& p01, typename S::F& p10,
                              typename S::F& p11) {
  if constexpr (!S::kPermute2) {
    return false;
  } else {
    using F = typename S::F;
    using I = typename S::I;
    using M = typename S::M;
    constexpr int N = S::N;
    // A little left of lane 0's column: the flow may pull later lanes left of it.
    const std::int32_t x = imax(0, imin(S::first(ix) - 4, g.ixmax + 2 - 2 * N));
    const I rel = S::subi(ix, S::seti(x));
    if (x + 2 * N > g.ixmax + 2 || !S::all(S::below(rel, 2 * N - 1))) return false;
    // The upper row: lane 0's, or the one above it (flow near zero rounds either way).
    const std::int32_t y0 = S::first(iy);
    const std::int32_t y = S::any(S::eqi(iy, S::seti(y0 - 1))) ? y0 - 1 : y0;
    const M upper = S::eqi(iy, S::seti(y));
    const bool one_row = S::all(upper);
    if (!one_row && !S::all(S::either(upper, S::eqi(iy, S::seti(y + 1))))) return false;
    const I rel1 = S::addi(rel, S::seti(1));
    const float* r0 = g.base + static_cast<Idx>(y) * g.step + x;
    const float* r1 = r0 + g.step;
    const F a0 = S::load(r0), a1 = S::load(r0 + N), b0 = S::load(r1), b1 = S::load(r1 + N);
    p00 = S::permute2(a0, a1, rel);
    p01 = S::permute2(a0, a1, rel1);
    p10 = S::permute2(b0, b1, rel);
    p11 = S::permute2(b0, b1, rel1);
    if (one_row) return true;
    // Lanes on row y + 1 (which is then at most the last but one) take rows y + 1 and y + 2.
    const float* r2 = r1 + g.step;
    const F c0 = S::load(r2), c1 = S::load(r2 + N);
    p00 = S::select(upper, p00, p10);
    p01 = S::select(upper, p01, p11);
    p10 = S::select(upper, p10, S::permute2(c0, c1, rel));
    p11 = S::select(upper, p11, S::permute2(c0, c1, rel1));
    return true;
  }
}

// The warp of one vector (or one pixel): its m and d.
template <class S>
ROIFLOW_INLINE void warp_values(const WarpGeometry& g, float fx0, float fy, const float* u,
                                const float* v, const float* i0, bool may_load_rows,
                                typename S::F& m, typename S::F& d) {
  using F = typename S::F;
  using I = typename S::I;
  const F zero = S::set1(0.f);
  const F sx =
      S::min(S::max(S::add(S::add(S::set1(fx0), S::iota()), S::load(u)), zero), S::set1(g.xhi));
  const F sy = S::min(S::max(S::add(S::set1(fy), S::load(v)), zero), S::set1(g.yhi));
  const I ix = S::mini(S::cvtt(sx), S::seti(g.ixmax));
  const I iy = S::mini(S::cvtt(sy), S::seti(g.iymax));
  const F fx = S::sub(sx, S::cvt(ix));
  const F fyv = S::sub(sy, S::cvt(iy));
  const I idx = S::addi(S::muli(iy, S::seti(static_cast<std::int32_t>(g.step))), ix);
  F p00, p01, p10, p11;
  const std::int32_t k0 = S::first(idx);
  if (may_load_rows && S::all(S::eqi(idx, S::addi(S::seti(k0), S::iotai())))) {
    // One row segment: the taps are four plain loads (the common case, smooth flow).
    const float* p = g.base + k0;
    p00 = S::load(p);
    p01 = S::load(p + 1);
    p10 = S::load(p + g.step);
    p11 = S::load(p + g.step + 1);
  } else if (!may_load_rows || !near_taps<S>(g, ix, iy, p00, p01, p10, p11)) {
    p00 = S::gather(g.base, idx);
    p01 = S::gather(g.base, S::addi(idx, S::seti(g.dx1)));
    p10 = S::gather(g.base, S::addi(idx, S::seti(g.dy1)));
    p11 = S::gather(g.base, S::addi(idx, S::seti(g.dy1 + g.dx1)));
  }
  const F top = S::madd(fx, S::sub(p01, p00), p00);
  const F bot = S::madd(fx, S::sub(p11, p10), p10);
  const F w1 = S::madd(fyv, S::sub(bot, top), top);
  const F a = S::load(i0);
  m = S::mul(S::set1(0.5f), S::add(a, w1));
  d = S::sub(w1, a);
}

template <class S>
ROIFLOW_INLINE void warp_block(const WarpGeometry& g, float fx0, float fy, const float* u,
                               const float* v, const float* i0, float* m, float* d,
                               bool may_load_rows) {
  typename S::F mv, dv;
  warp_values<S>(g, fx0, fy, u, v, i0, may_load_rows, mv, dv);
  S::store(m, mv);
  S::store(d, dv);
}

WarpGeometry warp_geometry(const LevelJob& L) {
  WarpGeometry g;
  g.base = L.i1;
  g.step = L.i1_step;
  g.xhi = static_cast<float>(L.cols - 1);
  g.yhi = static_cast<float>(L.rows - 1);
  g.ixmax = imax(0, L.cols - 2);
  g.iymax = imax(0, L.rows - 2);
  g.dx1 = L.cols > 1 ? 1 : 0;
  g.dy1 = L.rows > 1 ? static_cast<int>(L.i1_step) : 0;
  return g;
}

// Row y of the level (global), columns [x0, x1) of the rectangle (x1 <= w) into m, d (indexed
// from the rectangle's column 0), and the replicated columns m[-1] (with column 0) and m[w]
// (with column w - 1), d likewise.
void warp_row(const LevelJob& L, int y, const float* u, const float* v, float* m, float* d, int x0,
              int x1) {
  const WarpGeometry g = warp_geometry(L);
  const bool rows_ok = L.cols > 1 && L.rows > 1;
  const float* i0 = L.i0 + static_cast<Idx>(y) * L.i0_step + L.x0;
  const float fy = static_cast<float>(y);
  constexpr int N = Native::N;
  int x = x0;
  for (; x + N <= x1; x += N) {
    warp_block<Native>(g, static_cast<float>(L.x0 + x), fy, u + x, v + x, i0 + x, m + x, d + x,
                       rows_ok);
  }
  for (; x < x1; ++x) {
    warp_block<Scalar>(g, static_cast<float>(L.x0 + x), fy, u + x, v + x, i0 + x, m + x, d + x,
                       false);
  }
  if (L.mask_outside) {
    // A pixel whose sample left the frame asks for no change of its flow (It = 0) instead of
    // being pulled towards the replicated border.
    for (x = x0; x < x1; ++x) {
      const float sx = static_cast<float>(L.x0 + x) + u[x], sy = fy + v[x];
      const bool outside = sx < 0.f || sx > g.xhi || sy < 0.f || sy > g.yhi;
      m[x] = outside ? i0[x] : m[x];
      d[x] = outside ? 0.f : d[x];
    }
  }
  if (x0 == 0) {
    m[-1] = m[0];
    d[-1] = d[0];
  }
  if (x1 == L.w) {
    m[L.w] = m[L.w - 1];
    d[L.w] = d[L.w - 1];
  }
}

// ---------------------------------------------------------------------------------------------
// One output row: the window terms of the derivative-grid row that enters the vertical window
// (Ix², IxIy, Iy², Ix·r, Iy·r with r = Ix·ū + Iy·v̄ − It, the brightness equation linearised
// around the local flow, weighted by 1 / (1 + It² / s²) when robust) are stored in the ring and
// added into the vertical running sums, whose horizontal prefix sums give each window's sums as
// one difference; then the regularised 2x2 system (G + lambda I) w = b + lambda w_old of each
// pixel is solved, G and b the window means.
//
// Layouts, chosen so that the loops address everything from a few pointers with constant
// offsets and whole-vector aligned loads: the ring rows and the vertical sums hold the five
// channels of each vector of columns together ([vector][channel][lane]); the prefix sums and
// half-weight columns are planar, because the solve reads them at any column offset.

enum Deriv { kHornSchunck = 0, kScharr = 1, kCentral = 2, kOutside = 3 };

// Interleaved rows: channel c of the vector at column x.
ROIFLOW_INLINE float* at(float* row, int x, int c) {
  return row + kChannels * x + c * Native::N;
}
ROIFLOW_INLINE const float* at(const float* row, int x, int c) {
  return row + kChannels * x + c * Native::N;
}
// Ring rows: factor f of the vector at column x.
ROIFLOW_INLINE float* at_factor(float* row, int x, int f) {
  return row + kFactors * x + f * Native::N;
}
ROIFLOW_INLINE const float* at_factor(const float* row, int x, int f) {
  return row + kFactors * x + f * Native::N;
}

// The rows the entering derivative-grid row s is made of. Horn–Schunck: the pairs of warped rows
// s (pa) and s + 1 (pb). Grid stencils: warped rows s - 1, s, s + 1 (m0, m1, m2) and row s's d,
// u, v.
struct TermRows {
  const float *pa = nullptr, *pb = nullptr;
  const float *m0 = nullptr, *m1 = nullptr, *m2 = nullptr;
  const float *d1 = nullptr, *u1 = nullptr, *v1 = nullptr;
  int w = 1 << 30;  // the row's width: the factors of the lanes from w on are zero
  int lo = 0;       // the window's first column offset (windowed output only)
};

// The factors of row s's window terms at the vector of column x: Ix, Iy, r and, when robust,
// the weight (all zero outside the rectangle).
template <int kDeriv, bool kRobust>
ROIFLOW_INLINE void factors(const TermRows& t, int x, Native::F inv_s2, Native::F* f) {
  using S = Native;
  using F = S::F;
  if constexpr (kDeriv == kOutside) {
    for (int c = 0; c < kFactors; ++c)
      f[c] = S::set1(0.f);
    return;
  } else {
    F ix, iy, it, ub, vb;
    if constexpr (kDeriv == kHornSchunck) {
      const F half = S::set1(0.5f), quarter = S::set1(0.25f);
      ix = S::mul(half, S::add(S::load(at(t.pa, x, 0)), S::load(at(t.pb, x, 0))));
      iy = S::mul(half, S::sub(S::load(at(t.pb, x, 1)), S::load(at(t.pa, x, 1))));
      it = S::mul(quarter, S::add(S::load(at(t.pa, x, 2)), S::load(at(t.pb, x, 2))));
      ub = S::mul(quarter, S::add(S::load(at(t.pa, x, 3)), S::load(at(t.pb, x, 3))));
      vb = S::mul(quarter, S::add(S::load(at(t.pa, x, 4)), S::load(at(t.pb, x, 4))));
    } else if constexpr (kDeriv == kScharr) {
      const F k = S::set1(1.f / 32.f), three = S::set1(3.f), ten = S::set1(10.f);
      const F hx =
          S::madd(three, S::sub(S::load(t.m2 + x + 1), S::load(t.m2 + x - 1)),
                  S::madd(ten, S::sub(S::load(t.m1 + x + 1), S::load(t.m1 + x - 1)),
                          S::mul(three, S::sub(S::load(t.m0 + x + 1), S::load(t.m0 + x - 1)))));
      const F hy =
          S::madd(three, S::sub(S::load(t.m2 + x + 1), S::load(t.m0 + x + 1)),
                  S::madd(ten, S::sub(S::load(t.m2 + x), S::load(t.m0 + x)),
                          S::mul(three, S::sub(S::load(t.m2 + x - 1), S::load(t.m0 + x - 1)))));
      ix = S::mul(k, hx);
      iy = S::mul(k, hy);
      it = S::load(t.d1 + x);
      ub = S::load(t.u1 + x);
      vb = S::load(t.v1 + x);
    } else {
      const F half = S::set1(0.5f);
      ix = S::mul(half, S::sub(S::load(t.m1 + x + 1), S::load(t.m1 + x - 1)));
      iy = S::mul(half, S::sub(S::load(t.m2 + x), S::load(t.m0 + x)));
      it = S::load(t.d1 + x);
      ub = S::load(t.u1 + x);
      vb = S::load(t.v1 + x);
    }
    f[0] = ix;
    f[1] = iy;
    f[2] = S::sub(S::madd(iy, vb, S::mul(ix, ub)), it);
    if constexpr (kRobust) f[3] = S::recip(S::madd(S::mul(it, it), inv_s2, S::set1(1.f)));
  }
}

// The five window terms from their factors. The ring keeps the factors, not the terms (fewer
// bytes to store and to read back when the row leaves the window); every term is then
// recomputed by the same operations, so it is the same float.
template <bool kRobust>
ROIFLOW_INLINE void terms(const Native::F* f, Native::F* p) {
  using S = Native;
  Native::F wix = f[0], wiy = f[1];
  if constexpr (kRobust) {
    wix = S::mul(f[3], f[0]);
    wiy = S::mul(f[3], f[1]);
  }
  p[0] = S::mul(wix, f[0]);
  p[1] = S::mul(wix, f[1]);
  p[2] = S::mul(wiy, f[1]);
  p[3] = S::mul(wix, f[2]);
  p[4] = S::mul(wiy, f[2]);
}

// The terms of ring row `row` at the vector of column x.
template <bool kRobust>
ROIFLOW_INLINE void ring_terms(const float* row, int x, Native::F* p) {
  Native::F f[kFactors];
  for (int c = 0; c < (kRobust ? 4 : 3); ++c)
    f[c] = Native::load(at_factor(row, x, c));
  terms<kRobust>(f, p);
}

// The output of the vertical sum `sum` of vector x, channel c: the column sum (less half of the
// window's two end rows with kHalf: `top` the first row's term, `bottom` the last row's) into
// `col`, and its prefix sum, plus `carry` (the sums of the vectors before), into `prefix`.
template <bool kHalf>
ROIFLOW_INLINE void prefix_out(Native::F sum, Native::F bottom, Native::F top, int x, int c,
                               float* col, Idx col_stride, float* prefix, Idx pstride,
                               Native::F& carry) {
  using S = Native;
  Native::F column = sum;
  if constexpr (kHalf) {
    column = S::nmadd(S::set1(0.5f), S::add(top, bottom), column);
    S::store(col + c * col_stride + x, column);
  }
  // The carry is the same in every lane, so lane N - 1 of the sum is the in-vector total plus
  // the carry: taking the total out of the scan first keeps the lane broadcast off the chain
  // that runs from vector to vector (the same floats).
  const Native::F scan = S::prefix(column);
  S::store(prefix + c * pstride + x, S::add(scan, carry));
  carry = S::add(S::last(scan), carry);
}

// The carried state of a row's horizontal sums: one vector per channel for the prefix sums,
// three per channel for the windows (kWin 8 or 10).
constexpr int kCarryVectors = 3 * kChannels;

// Row s enters the window: its factors into the ring slot `ring` (which holds the leaving row's
// when kLeaving) and its terms into the vertical sums; with kPrefix, the sums' horizontal prefix
// sums (of the half-weight column sums when `top`, the window's first ring row, is given: `ring`
// is then its last) into `prefix` (planar, `pstride` apart) and the column sums into `col`; with
// kWin, the windows kWin wide themselves (window_step: vector x's at x - 2N, the row's last two
// by window_flush). The factors of the lanes from rows.w on are zero.
template <int kDeriv, bool kRobust, bool kLeaving, bool kPrefix, bool kHalf, int kWin = 0>
void enter_row_t(int x0, int x1, const TermRows& rows, float inv_s2_value, float* ring, float* acc,
                 const float* top, float* col, Idx col_stride, float* prefix, Idx pstride,
                 float* carry_mem) {
  using S = Native;
  using F = S::F;
  // Outside rows keep a zero weight too: a robust row leaving reads it.
  constexpr int kKept = kRobust || kDeriv == kOutside ? 4 : 3;
  constexpr int kState = kWin ? 3 * kChannels : kChannels;
  const TermRows t = rows;  // a local: the stores below could alias `rows`
  const F inv_s2 = S::set1(inv_s2_value);
  F carry[kState];
  for (int c = 0; c < kState; ++c)
    carry[c] = S::load(carry_mem + c * S::N);
  [[maybe_unused]] const WindowIndex<S> index(t.lo);
  for (int x = x0; x < x1; x += S::N) {
    F f[kFactors], term[kChannels], gone[kChannels], first[kChannels];
    factors<kDeriv, kRobust>(t, x, inv_s2, f);
    if constexpr (kDeriv != kOutside) {
      if (x + S::N > t.w) zero_lanes_from<S, kFactors>(f, t.w - x);
    }
    terms<kRobust>(f, term);
    if constexpr (kLeaving) ring_terms<kRobust>(ring, x, gone);
    if constexpr (kHalf) ring_terms<kRobust>(top, x, first);
    for (int c = 0; c < kKept; ++c)
      S::store(at_factor(ring, x, c), f[c]);
    for (int c = 0; c < kChannels; ++c) {
      float* ac = at(acc, x, c);
      const F old = S::load(ac);
      const F sum = kLeaving ? S::add(old, S::sub(term[c], gone[c])) : S::add(old, term[c]);
      S::store(ac, sum);
      if constexpr (kPrefix && kWin != 0) {
        S::store(prefix + c * pstride + x - 2 * S::N,
                 window_step<S, kWin>(sum, carry + 3 * c, index));
      } else if constexpr (kPrefix) {
        prefix_out<kHalf>(sum, term[c], first[c], x, c, col, col_stride, prefix, pstride, carry[c]);
      }
    }
  }
  for (int c = 0; c < kState; ++c)
    S::store(carry_mem + c * S::N, carry[c]);
}

// Fresh window sums: acc = the terms of the window's ring rows added top to bottom (then their
// prefix sums as in enter_row, or with kWin their windows, unless `prefix` is null). A running
// sum's rounding depends on where it started: summing afresh every `stripe` rows makes every
// row independent of where its pass began.
template <bool kRobust, int kWin>
void resum_row_t(int x0, int x1, const float* const* row_list, int count, float* acc,
                 const float* top, const float* bot, float* col, Idx col_stride, float* prefix,
                 Idx pstride, float* carry_mem, int lo) {
  const float* rows[64];
  for (int r = 0; r < count; ++r)
    rows[r] = row_list[r];
  using S = Native;
  using F = S::F;
  constexpr int kState = kWin ? 3 * kChannels : kChannels;
  F carry[kState];
  for (int c = 0; c < kState; ++c)
    carry[c] = S::load(carry_mem + c * S::N);
  [[maybe_unused]] const WindowIndex<S> index(lo);
  for (int x = x0; x < x1; x += S::N) {
    F sum[kChannels], term[kChannels];
    ring_terms<kRobust>(rows[0], x, sum);
    for (int r = 1; r < count; ++r) {
      ring_terms<kRobust>(rows[r], x, term);
      for (int c = 0; c < kChannels; ++c)
        sum[c] = S::add(sum[c], term[c]);
    }
    for (int c = 0; c < kChannels; ++c)
      S::store(at(acc, x, c), sum[c]);
    if (!prefix) continue;
    if constexpr (kWin != 0) {
      for (int c = 0; c < kChannels; ++c) {
        S::store(prefix + c * pstride + x - 2 * S::N,
                 window_step<S, kWin>(sum[c], carry + 3 * c, index));
      }
    } else if (top) {
      F first[kChannels], last[kChannels];
      ring_terms<kRobust>(top, x, first);
      ring_terms<kRobust>(bot, x, last);
      for (int c = 0; c < kChannels; ++c) {
        prefix_out<true>(sum[c], last[c], first[c], x, c, col, col_stride, prefix, pstride,
                         carry[c]);
      }
    } else {
      for (int c = 0; c < kChannels; ++c)
        prefix_out<false>(sum[c], sum[c], sum[c], x, c, col, col_stride, prefix, pstride, carry[c]);
    }
  }
  for (int c = 0; c < kState; ++c)
    S::store(carry_mem + c * S::N, carry[c]);
}

template <bool kRobust>
void resum_row_w(int win, int x0, int x1, const float* const* row_list, int count, float* acc,
                 const float* top, const float* bot, float* col, Idx col_stride, float* prefix,
                 Idx pstride, float* carry_mem, int lo) {
  if constexpr (Native::kPermute2) {
    if (win == 8) {
      return resum_row_t<kRobust, 8>(x0, x1, row_list, count, acc, top, bot, col, col_stride,
                                     prefix, pstride, carry_mem, lo);
    }
    if (win == 10) {
      return resum_row_t<kRobust, 10>(x0, x1, row_list, count, acc, top, bot, col, col_stride,
                                      prefix, pstride, carry_mem, lo);
    }
  }
  resum_row_t<kRobust, 0>(x0, x1, row_list, count, acc, top, bot, col, col_stride, prefix, pstride,
                          carry_mem, lo);
}

// `win`: 0 for prefix sums, else the width of the windows made (window_width).
void resum_row(bool robust, int win, int x0, int x1, const float* const* row_list, int count,
               float* acc, const float* top, const float* bot, float* col, Idx col_stride,
               float* prefix, Idx pstride, float* carry_mem, int lo) {
  if (robust) {
    return resum_row_w<true>(win, x0, x1, row_list, count, acc, top, bot, col, col_stride, prefix,
                             pstride, carry_mem, lo);
  }
  resum_row_w<false>(win, x0, x1, row_list, count, acc, top, bot, col, col_stride, prefix, pstride,
                     carry_mem, lo);
}

struct SolveRow {
  int w;
  const float* prefix;  // channel c at prefix + c * pstride; window = p[x + hi] - p[x + lo - 1]
  Idx pstride;
  const float* col;  // half-weight: subtract half of col[x + lo] and col[x + hi]
  Idx col_stride;
  int lo, hi;
  const float* inv_cx;
  float inv_cy, lambda;
  const float *uo, *vo;
  float *un, *vn, *conf;
  float* flow;    // non-null: (u, v) interleaved here instead of un, vn (rows not padded)
  bool windowed;  // prefix holds the window sums themselves (window_row), aligned with x
};

// The window sum p[x + hi] - p[x + lo - 1] from the prefix sums' aligned vectors at x - N
// (`before`), x and x + N: lanes at_hi of (here, after) less lanes at_lo of (before, here).
template <class S>
ROIFLOW_INLINE typename S::F window_sum(typename S::F before, typename S::F here,
                                        typename S::F after, typename S::I at_hi,
                                        typename S::I at_lo) {
  if constexpr (S::kPermute2) {
    return S::sub(S::permute2(here, after, at_hi), S::permute2(before, here, at_lo));
  } else {
    return S::sub(here, before);  // (not called: only with two-vector permutes)
  }
}

template <bool kHalf, bool kConfidence, bool kInterleaved, bool kWindowed = false>
void solve_row_t(const SolveRow& q, int x0, int x1) {
  using S = Native;
  using F = S::F;
  // Locals, not q's fields: the stores below could alias q, and the compiler would reload every
  // field per vector.
  const float* p[kChannels];
  const float* col[kChannels];
  for (int c = 0; c < kChannels; ++c) {
    p[c] = q.prefix + c * q.pstride + q.hi;
    col[c] = kHalf ? q.col + c * q.col_stride : nullptr;
  }
  const Idx span = q.hi - q.lo + 1;  // from p[x + lo - 1] to p[x + hi]
  const int lo = q.lo, hi = q.hi;
  const float* inv_cx = q.inv_cx;
  const float *uo = q.uo, *vo = q.vo;
  float *un = q.un, *vn = q.vn, *conf = q.conf, *flow = q.flow;
  const int w = q.w;
  const F lambda = S::set1(q.lambda), inv_cy = S::set1(q.inv_cy), half = S::set1(0.5f);
  // Without half weights and with both window ends less than a vector from the column (always
  // with two-vector permutes, windows up to 31 wide), the prefix sums at x + hi and x + lo - 1
  // come from the aligned vectors at x - N, x and x + N, kept in registers from one vector to
  // the next and permuted: the same floats as the loads N floats long at those columns, each of
  // which would span two cache lines.
  constexpr bool kAligned = S::kPermute2 && !kHalf && !kWindowed;
  [[maybe_unused]] F before[kChannels], here[kChannels];
  [[maybe_unused]] S::I at_hi, at_lo;
  const bool aligned = kAligned && hi >= 0 && hi < S::N && lo <= 0 && lo > -S::N;
  if constexpr (kAligned) {
    if (aligned) {
      at_hi = S::addi(S::iotai(), S::seti(hi));
      at_lo = S::addi(S::iotai(), S::seti(S::N + lo - 1));
      for (int c = 0; c < kChannels; ++c) {
        before[c] = S::load(p[c] - hi + x0 - S::N);
        here[c] = S::load(p[c] - hi + x0);
      }
    }
  }
  // Whole vectors: the lanes past w land in the rows' padding.
  for (int x = x0; x < x1; x += S::N) {
    F s[kChannels];
    for (int c = 0; c < kChannels; ++c) {
      if constexpr (kWindowed) {
        s[c] = S::load(p[c] - hi + x);
        continue;
      }
      if constexpr (kAligned) {
        if (aligned) {
          const F after = S::load(p[c] - hi + x + S::N);
          s[c] = window_sum<S>(before[c], here[c], after, at_hi, at_lo);
          before[c] = here[c];
          here[c] = after;
          continue;
        }
      }
      s[c] = S::sub(S::load(p[c] + x), S::load(p[c] + x - span));
      if constexpr (kHalf) {
        s[c] = S::nmadd(half, S::add(S::load(col[c] + x + lo), S::load(col[c] + x + hi)), s[c]);
      }
    }
    const F n = S::mul(S::load(inv_cx + x), inv_cy);
    const F gxx = S::mul(s[0], n), gxy = S::mul(s[1], n), gyy = S::mul(s[2], n);
    const F a = S::add(gxx, lambda), dd = S::add(gyy, lambda);
    const F ex = S::madd(s[3], n, S::mul(lambda, S::load(uo + x)));
    const F ey = S::madd(s[4], n, S::mul(lambda, S::load(vo + x)));
    const F inv_det = S::recip(S::nmadd(gxy, gxy, S::mul(a, dd)));
    const F nu = S::mul(S::nmadd(gxy, ey, S::mul(dd, ex)), inv_det);
    const F nv = S::mul(S::nmadd(gxy, ex, S::mul(a, ey)), inv_det);
    F cf = S::set1(0.f);
    if constexpr (kConfidence) {
      const F hd = S::mul(half, S::sub(gxx, gyy));
      const F root = S::sqrt(S::madd(hd, hd, S::mul(gxy, gxy)));
      cf = S::max(S::set1(0.f), S::sub(S::mul(half, S::add(gxx, gyy)), root));
    }
    if constexpr (kInterleaved) {
      F first, second;
      S::zip(nu, nv, first, second);
      if (x + S::N <= w) {
        S::store(flow + 2 * x, first);
        S::store(flow + 2 * x + S::N, second);
        if constexpr (kConfidence) S::store(conf + x, cf);
      } else {
        // The rows of the result end at w: the last vector's lanes go one by one.
        alignas(64) float pairs[2 * S::N], conf_lanes[S::N];
        S::store(pairs, first);
        S::store(pairs + S::N, second);
        S::store(conf_lanes, cf);
        for (int i = 0; x + i < w; ++i) {
          flow[2 * (x + i)] = pairs[2 * i];
          flow[2 * (x + i) + 1] = pairs[2 * i + 1];
          if constexpr (kConfidence) conf[x + i] = conf_lanes[i];
        }
      }
    } else {
      S::store(un + x, nu);
      S::store(vn + x, nv);
      if constexpr (kConfidence) S::store(conf + x, cf);
    }
  }
}

template <bool kHalf>
void solve_row_h(const SolveRow& q, int x0, int x1) {
  if constexpr (!kHalf && Native::kPermute2) {
    if (q.windowed) {
      if (q.flow) {
        if (q.conf) return solve_row_t<false, true, true, true>(q, x0, x1);
        return solve_row_t<false, false, true, true>(q, x0, x1);
      }
      if (q.conf) return solve_row_t<false, true, false, true>(q, x0, x1);
      return solve_row_t<false, false, false, true>(q, x0, x1);
    }
  }
  if (q.flow) {
    if (q.conf) return solve_row_t<kHalf, true, true>(q, x0, x1);
    return solve_row_t<kHalf, false, true>(q, x0, x1);
  }
  if (q.conf) return solve_row_t<kHalf, true, false>(q, x0, x1);
  solve_row_t<kHalf, false, false>(q, x0, x1);
}

void solve_row(const SolveRow& q, int x0, int x1) {
  if (x0 >= x1) return;
  if (q.col) return solve_row_h<true>(q, x0, x1);
  solve_row_h<false>(q, x0, x1);
}

using EnterFn = void (*)(int, int, const TermRows&, float, float*, float*, const float*, float*,
                         Idx, float*, Idx, float*);

template <int kDeriv, bool kRobust, bool kLeaving>
EnterFn pick_enter_output(bool prefix, bool half, int win) {
  if (!prefix) return enter_row_t<kDeriv, kRobust, kLeaving, false, false>;
  if constexpr (Native::kPermute2) {
    if (win == 8) return enter_row_t<kDeriv, kRobust, kLeaving, true, false, 8>;
    if (win == 10) return enter_row_t<kDeriv, kRobust, kLeaving, true, false, 10>;
  }
  return half ? enter_row_t<kDeriv, kRobust, kLeaving, true, true>
              : enter_row_t<kDeriv, kRobust, kLeaving, true, false>;
}

template <int kDeriv, bool kRobust>
EnterFn pick_enter_flags(bool leaving, bool prefix, bool half, int win) {
  return leaving ? pick_enter_output<kDeriv, kRobust, true>(prefix, half, win)
                 : pick_enter_output<kDeriv, kRobust, false>(prefix, half, win);
}

// With `win` (window_width's, not 0: two-vector permutes, no half weights), the output is the
// windows' sums instead of the prefix sums.
EnterFn pick_enter(int deriv, bool robust, bool leaving, bool prefix, bool half, int win) {
  switch (deriv) {
    case kHornSchunck:
      return robust ? pick_enter_flags<kHornSchunck, true>(leaving, prefix, half, win)
                    : pick_enter_flags<kHornSchunck, false>(leaving, prefix, half, win);
    case kScharr:
      return robust ? pick_enter_flags<kScharr, true>(leaving, prefix, half, win)
                    : pick_enter_flags<kScharr, false>(leaving, prefix, half, win);
    case kCentral:
      return robust ? pick_enter_flags<kCentral, true>(leaving, prefix, half, win)
                    : pick_enter_flags<kCentral, false>(leaving, prefix, half, win);
    default:  // (the leaving row's terms are recomputed with its weight when robust)
      return robust ? pick_enter_flags<kOutside, true>(leaving, prefix, half, win)
                    : pick_enter_flags<kOutside, false>(leaving, prefix, half, win);
  }
}

}  // namespace
}  // namespace roiflow::flow::detail
