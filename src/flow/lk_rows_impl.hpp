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
// means of two neighbours (borders replicate), all doubled. Coarse pixels j and j + 1 come
// straight from a and b for every pair of output vectors (no row of copies stored and read back
// one column off). `temp` is not used (kept for the table's signature).
template <class S>
ROIFLOW_INLINE typename S::F upsampled_coarse(const float* a, const float* b, typename S::F fy) {
  const typename S::F va = S::load(a);
  return S::mul(S::set1(2.f), S::madd(fy, S::sub(S::load(b), va), va));
}

template <bool kBetween>
void upsample_row_t(const float* a, const float* b, float fy, int n, int k0, int width,
                    float* out) {
  using S = Native;
  using F = S::F;
  constexpr int N = S::N;
  const F vfy = S::set1(fy), half = S::set1(0.5f);
  const int pairs = width / 2;
  int i = 0;
  // Vectors whose coarse pixels k0 + i .. k0 + i + N all lie in the row.
  for (; i + N <= pairs && k0 + i + N < n; i += N) {
    const F c0 = upsampled_coarse<S>(a + k0 + i, b + k0 + i, vfy);
    const F c1 = upsampled_coarse<S>(a + k0 + i + 1, b + k0 + i + 1, vfy);
    const F mean = S::mul(half, S::add(c0, c1));
    F lo, hi;
    if constexpr (kBetween) {
      S::zip(mean, c1, lo, hi);
    } else {
      S::zip(c0, mean, lo, hi);
    }
    S::store(out + 2 * i, lo);
    S::store(out + 2 * i + N, hi);
  }
  // The rest lane by lane, the last coarse pixel replicated past the row's end.
  auto coarse = [&](int j) {
    j = imin(j, n - 1);
    return upsampled_coarse<Scalar>(a + j, b + j, fy);
  };
  for (; i <= pairs; ++i) {
    const int j = k0 + i;
    const float c0 = coarse(j), c1 = coarse(j + 1);
    const float mean = 0.5f * (c0 + c1);
    const float first = kBetween ? mean : c0;
    if (i < pairs) {
      out[2 * i] = first;
      out[2 * i + 1] = kBetween ? c1 : mean;
    } else if (width & 1) {
      out[width - 1] = first;
    }
  }
}

void upsample_row(const float* a, const float* b, float fy, int n, int k0, bool between, int width,
                  float* /*temp*/, float* out) {
  if (between) return upsample_row_t<true>(a, b, fy, n, k0, width, out);
  upsample_row_t<false>(a, b, fy, n, k0, width, out);
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

// (The taps and row pointers are copied to locals first: `t` is a float pointer too, and the
// compiler would otherwise reload every tap after each store.)
template <int R>
void smooth_h_t(const float* p, const float* k_in, int w, float* t) {
  float k[R + 1];
  for (int j = 0; j <= R; ++j)
    k[j] = k_in[j];
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
void smooth_v_t(const float* const* rows_in, const float* k_in, int w, float* o) {
  float k[R + 1];
  const float* rows[2 * R + 1];
  for (int j = 0; j <= R; ++j)
    k[j] = k_in[j];
  for (int j = 0; j <= 2 * R; ++j)
    rows[j] = rows_in[j];
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
