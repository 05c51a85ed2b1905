// Direct horizontal window sums for dense LK's row kernels (lk_kernels_impl.hpp): each channel's
// column sums go through window_step vector by vector, and out come the sums of windows 8 or 10
// columns wide, two vectors later, without prefix sums. Included by lk_kernels_impl.hpp only,
// once per instruction set; used where two-vector permutes exist (AVX-512). Everything here has
// internal linkage. Example, the windows of one channel's column sums `col` (w columns, zero
// past them) into `win` for a window from lo = -5 to hi = 4:
//
//   const WindowIndex<Native> k(-5);
//   Native::F st[3] = {Native::set1(0.f), Native::set1(0.f), Native::set1(0.f)};
//   for (int x = 0; x < w + 2 * Native::N; x += Native::N) {
//     const Native::F c = x < w ? Native::load(col + x) : Native::set1(0.f);
//     const Native::F s = window_step<Native, 10>(c, st, k);
//     if (x >= 2 * Native::N) Native::store(win + x - 2 * Native::N, s);
//   }
#pragma once

#include <cstddef>

#include "flow/simd.hpp"

namespace roiflow::flow::detail {
namespace {

using simd::Native;

// Horizontal window sums straight from the column sums, for windows 8 or 10 wide (the even
// patches on the half-pixel grid) with two-vector permutes: per vector and channel, pairs
// a2[x] = c[x] + c[x + 1], blocks a4[x] = a2[x] + a2[x + 2], and the window as two blocks (and
// a pair), each a permute of two neighbouring vectors. Fewer operations than a prefix scan and
// the solve's difference of two permuted prefix vectors, no chain from vector to vector, and no
// cancellation of large prefix sums. Returns the width (8 or 10) where this applies, else 0.
int window_width(int lo, int hi, int n) {
  const int width = hi - lo + 1;
  if (width != 8 && width != 10) return 0;
  // Blocks at lo and lo + 4 from the vector before and this one; the pair at lo + 8 from this
  // one and the next.
  if (lo <= -n || lo + 4 > 0) return 0;
  if (width == 10 && (lo + 8 < 0 || lo + 9 >= n)) return 0;
  return width;
}

// The permute indices of window_step for a window starting at column offset lo.
template <class S>
struct WindowIndex {
  typename S::I block0, block1, pair, two;
  explicit WindowIndex(int lo) {
    block0 = S::addi(S::iotai(), S::seti(S::N + lo));
    block1 = S::addi(S::iotai(), S::seti(S::N + lo + 4));
    pair = S::addi(S::iotai(), S::seti(lo + 8));
    two = S::addi(S::iotai(), S::seti(2));
  }
};

// Step t of a channel's horizontal windows: column vector c_t enters; the pairs of vector
// t - 1, the blocks of t - 2 are made, and the windows of vector t - 2 returned. The state:
// st[0] = c_{t-1}, st[1] = a2_{t-2}, st[2] = a4_{t-3} (zero before column 0).
template <class S, int kWidth>
ROIFLOW_INLINE typename S::F window_step(typename S::F c, typename S::F* st,
                                         const WindowIndex<S>& k) {
  using F = typename S::F;
  const F a2 = S::add(st[0], S::next1(st[0], c));             // a2_{t-1}
  const F a4 = S::add(st[1], S::permute2(st[1], a2, k.two));  // a4_{t-2}
  F sum = S::add(S::permute2(st[2], a4, k.block0), S::permute2(st[2], a4, k.block1));
  if constexpr (kWidth == 10) sum = S::add(sum, S::permute2(st[1], a2, k.pair));
  st[0] = c;
  st[1] = a2;
  st[2] = a4;
  return sum;
}

// The windows of the row's last two vectors (those from xe - 2N) of kCount channels (state
// three vectors per channel, their windows `wstride` apart): two steps of zero columns.
template <int kWidth, int kCount>
void window_flush(int xe, int lo, float* state_mem, float* win, std::ptrdiff_t wstride) {
  using S = Native;
  if constexpr (S::kPermute2) {
    const WindowIndex<S> k(lo);
    for (int c = 0; c < kCount; ++c) {
      S::F st[3];
      for (int i = 0; i < 3; ++i)
        st[i] = S::load(state_mem + (3 * c + i) * S::N);
      S::store(win + c * wstride + xe - 2 * S::N, window_step<S, kWidth>(S::set1(0.f), st, k));
      S::store(win + c * wstride + xe - S::N, window_step<S, kWidth>(S::set1(0.f), st, k));
    }
  } else {
    (void)xe, (void)lo, (void)state_mem, (void)win, (void)wstride;
  }
}

// Vectors f[0, kCount) set to zero in the lanes from n on (two-vector permute sets only: the others
// make no windows, and the prefix sums past the row's end are replaced anyway).
template <class S, int kCount>
ROIFLOW_INLINE void zero_lanes_from(typename S::F* f, int n) {
  if constexpr (S::kPermute2) {
    const auto inside = S::below(S::iotai(), n);
    for (int c = 0; c < kCount; ++c)
      f[c] = S::select(inside, f[c], S::set1(0.f));
  } else {
    (void)f, (void)n;
  }
}

}  // namespace
}  // namespace roiflow::flow::detail
