// The Horn–Schunck pairs of a warped row (warp_row's m and d, the flow's u and v): from a stored
// row (hs_pairs) or, for a whole row, from the warp's registers (warp_pairs_row). Included by
// lk_band_impl.hpp only, once per instruction set: everything here has internal linkage.
#pragma once

#include "flow/lk_kernels.hpp"
#include "flow/lk_kernels_impl.hpp"
#include "flow/simd.hpp"

namespace roiflow::flow::detail {
namespace {

// The pairs of the vector at column x from its m, d, u, v (…0) and the next vector's (…2); then
// the next vector becomes the current one.
ROIFLOW_INLINE void store_pairs(float* pairs, int x, Native::F& m0, Native::F& d0, Native::F& u0,
                                Native::F& v0, Native::F m2, Native::F d2, Native::F u2,
                                Native::F v2) {
  using S = Native;
  const Native::F m1 = S::next1(m0, m2);
  S::store(at(pairs, x, 0), S::sub(m1, m0));
  S::store(at(pairs, x, 1), S::add(m0, m1));
  S::store(at(pairs, x, 2), S::add(d0, S::next1(d0, d2)));
  S::store(at(pairs, x, 3), S::add(u0, S::next1(u0, u2)));
  S::store(at(pairs, x, 4), S::add(v0, S::next1(v0, v2)));
  m0 = m2;
  d0 = d2;
  u0 = u2;
  v0 = v2;
}

// Horn–Schunck works on the 2x2x2 cube between warped rows s, s + 1 and columns x, x + 1 (grid
// at +1/2). Each warped row's column pairs are formed once (it serves two derivative-grid rows):
// Dm = m[x+1] - m[x], Sm = m[x] + m[x+1], Sd, Su, Sv likewise (interleaved like the ring). Flow
// rows: column w holds column w - 1, so x + 1 is the replicated neighbour at the last column.
// Column x + 1 comes from the next vector in registers (aligned loads only: a load one column
// off spans two vectors the warp has just stored, and waits for both to leave the store queue).
void hs_pairs(int x0, int x1, const float* m, const float* d, const float* u, const float* v,
              float* pairs) {
  using S = Native;
  using F = S::F;
  if (x0 >= x1) return;
  F m0 = S::load(m + x0), d0 = S::load(d + x0), u0 = S::load(u + x0), v0 = S::load(v + x0);
  for (int x = x0; x < x1; x += S::N) {
    const int n = x + S::N;
    const F m2 = S::load(m + n), d2 = S::load(d + n), u2 = S::load(u + n), v2 = S::load(v + n);
    store_pairs(pairs, x, m0, d0, u0, v0, m2, d2, u2, v2);
  }
}

// Warped row y whole and its Horn–Schunck pairs up to the vector end xe: warp_row(L, y, u, v, m,
// d, 0, L.w) then hs_pairs(0, xe, ...), the same floats, but each vector's pairs are made from the
// warp's registers as the next vector is warped (its m and d are neither stored nor loaded back;
// a load of m one vector on would wait for the store just made). The last vectors go through
// memory as before. m and d of the bulk are not stored: only the Horn–Schunck pairs read them.
void warp_pairs_row(const LevelJob& L, int y, const float* u, const float* v, float* m, float* d,
                    float* pairs, int xe) {
  using S = Native;
  using F = S::F;
  constexpr int N = S::N;
  const int w = L.w;
  if (L.mask_outside || L.cols < 2 || L.rows < 2 || w < 2 * N) {
    warp_row(L, y, u, v, m, d, 0, w);
    return hs_pairs(0, xe, m, d, u, v, pairs);
  }
  const WarpGeometry g = warp_geometry(L);
  const float* i0 = L.i0 + static_cast<Idx>(y) * L.i0_step + L.x0;
  const float fy = static_cast<float>(y);
  F m0, d0;
  warp_values<S>(g, static_cast<float>(L.x0), fy, u, v, i0, true, m0, d0);
  F u0 = S::load(u), v0 = S::load(v);
  int x = N;
  for (; x + N <= w; x += N) {
    F m2, d2;
    warp_values<S>(g, static_cast<float>(L.x0 + x), fy, u + x, v + x, i0 + x, true, m2, d2);
    const F u2 = S::load(u + x), v2 = S::load(v + x);
    store_pairs(pairs, x - N, m0, d0, u0, v0, m2, d2, u2, v2);
  }
  // The last whole vector (at x - N), the columns after it and the replicated column w through
  // memory, as warp_row leaves them; their pairs as hs_pairs makes them.
  S::store(m + x - N, m0);
  S::store(d + x - N, d0);
  for (int c = x; c < w; ++c) {
    warp_block<Scalar>(g, static_cast<float>(L.x0 + c), fy, u + c, v + c, i0 + c, m + c, d + c,
                       false);
  }
  m[w] = m[w - 1];
  d[w] = d[w - 1];
  hs_pairs(x - N, xe, m, d, u, v, pairs);
}

}  // namespace
}  // namespace roiflow::flow::detail
