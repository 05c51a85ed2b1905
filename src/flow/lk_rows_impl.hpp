// Row kernels of the pyramid and of the x2 upsampling of a level's flow, written once against
// simd.hpp; exported through lk_kernels.hpp's table. Included by lk_band_impl.hpp only, once per
// instruction set: everything here has internal linkage.
#pragma once

#include <cstdint>

#include "flow/lk_kernels.hpp"
#include "flow/lk_kernels_impl.hpp"
#include "flow/simd.hpp"

namespace roiflow::flow::detail {
namespace {

// Row y of the finer level's flow component from the coarser one: a = coarse row y0, b = row
// y0 + 1 (or y0 again), fy in {0, 1/2}; n coarse pixels; the finer row starts at coarse pixel k0
// (between two coarse pixels when `between`) and is `width` long. Pixel x of the finer level sits
// at x / 2 of the coarser one, so the finer pixels alternate between copies of a coarse pixel and
// means of two neighbours (borders replicate), all doubled. `temp`: 2 * (n + 2) + 2 * lanes floats.
void upsample_row(const float* a, const float* b, float fy, int n, int k0, bool between, int width,
                  float* temp, float* out) {
  using S = Native;
  using F = S::F;
  constexpr int N = S::N;
  float* copy = temp;
  float* mean = temp + round_up(n + 2, N) + N;
  const F two = S::set1(2.f), half = S::set1(0.5f), vfy = S::set1(fy);
  int x = 0;
  for (; x + N <= n; x += N) {
    const F va = S::load(a + x);
    S::store(copy + x, S::mul(two, S::madd(vfy, S::sub(S::load(b + x), va), va)));
  }
  for (; x < n; ++x)
    copy[x] = 2.f * Scalar::madd(fy, b[x] - a[x], a[x]);
  copy[n] = copy[n + 1] = copy[n - 1];
  for (x = 0; x + N <= n + 1; x += N)
    S::store(mean + x, S::mul(half, S::add(S::load(copy + x), S::load(copy + x + 1))));
  for (; x <= n; ++x)
    mean[x] = 0.5f * (copy[x] + copy[x + 1]);
  const float* first = between ? mean + k0 : copy + k0;
  const float* second = between ? copy + k0 + 1 : mean + k0;
  const int pairs = width / 2;
  int i = 0;
  for (; i + N <= pairs; i += N) {
    F lo, hi;
    S::zip(S::load(first + i), S::load(second + i), lo, hi);
    S::store(out + 2 * i, lo);
    S::store(out + 2 * i + N, hi);
  }
  for (; i < pairs; ++i) {
    out[2 * i] = first[i];
    out[2 * i + 1] = second[i];
  }
  if (width & 1) out[width - 1] = first[pairs];
}

// 8-bit row to floats in [0, 1].
void unit_row_u8(const std::uint8_t* src, int w, float* dst) {
  using S = Native;
  const S::F scale = S::set1(1.f / 255.f);
  int x = 0;
  for (; x + S::N <= w; x += S::N)
    S::store(dst + x, S::mul(S::load_u8(src + x), scale));
  for (; x < w; ++x)
    dst[x] = static_cast<float>(src[x]) * (1.f / 255.f);
}

// Symmetric filter of radius R, horizontally: t[x] = k[R] p[x + R] + sum_j<R k[j] (p[x + j] +
// p[x + 2R - j]), p padded with R pixels each side.
template <int R, class S>
ROIFLOW_INLINE typename S::F filter_h(const float* p, const float* k, int x) {
  typename S::F acc = S::mul(S::set1(k[R]), S::load(p + x + R));
  for (int j = 0; j < R; ++j)
    acc = S::madd(S::set1(k[j]), S::add(S::load(p + x + j), S::load(p + x + 2 * R - j)), acc);
  return acc;
}

template <int R>
void smooth_h_t(const float* p, const float* k, int w, float* t) {
  int x = 0;
  for (; x + Native::N <= w; x += Native::N)
    Native::store(t + x, filter_h<R, Native>(p, k, x));
  for (; x < w; ++x)
    t[x] = filter_h<R, Scalar>(p, k, x);
}

// The same vertically over the 2R + 1 rows rows[0 .. 2R].
template <int R, class S>
ROIFLOW_INLINE typename S::F filter_v(const float* const* rows, const float* k, int x) {
  typename S::F acc = S::mul(S::set1(k[R]), S::load(rows[R] + x));
  for (int j = 0; j < R; ++j)
    acc = S::madd(S::set1(k[j]), S::add(S::load(rows[j] + x), S::load(rows[2 * R - j] + x)), acc);
  return acc;
}

template <int R>
void smooth_v_t(const float* const* rows, const float* k, int w, float* o) {
  int x = 0;
  for (; x + Native::N <= w; x += Native::N)
    Native::store(o + x, filter_v<R, Native>(rows, k, x));
  for (; x < w; ++x)
    o[x] = filter_v<R, Scalar>(rows, k, x);
}

void smooth_h(const float* p, const float* k, int radius, int w, float* t) {
  switch (radius) {
    case 1:
      return smooth_h_t<1>(p, k, w, t);
    case 2:
      return smooth_h_t<2>(p, k, w, t);
    case 3:
      return smooth_h_t<3>(p, k, w, t);
    default:
      return smooth_h_t<4>(p, k, w, t);
  }
}

void smooth_v(const float* const* rows, const float* k, int radius, int w, float* o) {
  switch (radius) {
    case 1:
      return smooth_v_t<1>(rows, k, w, o);
    case 2:
      return smooth_v_t<2>(rows, k, w, o);
    case 3:
      return smooth_v_t<3>(rows, k, w, o);
    default:
      return smooth_v_t<4>(rows, k, w, o);
  }
}

}  // namespace
}  // namespace roiflow::flow::detail
