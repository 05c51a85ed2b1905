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

// cv::pyrDown of float images, bit for bit, as OpenCV's 128-bit SIMD build computes it: [1 4 6 4 1]
// on every second column of a row, then on every second row, x 1/256, borders reflected (101).
// OpenCV's vector loops (4 lanes) and its scalar code sum in different orders; which columns
// each takes is reproduced (tested against cv::pyrDown on frames of many sizes). Used with
// two-vector permutes only (the even and odd columns of two vectors).

// The scalar order: src[2x] * 6 + (src[2x - 1] + src[2x + 1]) * 4 + src[2x - 2] + src[2x + 2].
ROIFLOW_INLINE float down_scalar(float r0, float r1, float r2, float r3, float r4) {
  return r2 * 6.f + (r1 + r3) * 4.f + r0 + r4;
}
// The vector order: r2 * 6 + ((r1 + r3) * 4 + (r0 + r4)), no fused multiply-add.
template <class S>
ROIFLOW_INLINE typename S::F down_h_vector(typename S::F r0, typename S::F r1, typename S::F r2,
                                           typename S::F r3, typename S::F r4) {
  return S::add(S::mul(r2, S::set1(6.f)),
                S::add(S::mul(S::add(r1, r3), S::set1(4.f)), S::add(r0, r4)));
}
// Vertically: ((r1 + r3) + r2) * 4 + ((r0 + r4) + (r2 + r2)), then x 1/256.
template <class S>
ROIFLOW_INLINE typename S::F down_v_vector(typename S::F r0, typename S::F r1, typename S::F r2,
                                           typename S::F r3, typename S::F r4) {
  const typename S::F t = S::add(S::mul(S::add(S::add(r1, r3), r2), S::set1(4.f)),
                                 S::add(S::add(r0, r4), S::add(r2, r2)));
  return S::mul(t, S::set1(1.f / 256.f));
}

// The columns x = 1, 1 + N, ... of pyr_down_h's vector order whose loads stay inside the row,
// from the even and odd columns of two vectors (E, O: columns 2x - 2 + 2i and 2x - 1 + 2i) and
// those of the next block (E', O'): r0 = E, r1 = O, r2 = E shifted one lane on into E', r3 the
// same of O, r4 two lanes on. Two loads and five shuffles per vector; returns the first column
// not made.
template <class S>
int pyr_down_h_vectors(const float* src, int w, int vend, float* row) {
  int x = 1;
  if constexpr (S::kPermute2) {
    using F = typename S::F;
    using I = typename S::I;
    constexpr int N = S::N;
    const I even = S::addi(S::iotai(), S::iotai());
    const I odd = S::addi(even, S::seti(1));
    const I two = S::addi(S::iotai(), S::seti(2));
    // (The next block's loads end at column 2x + 4N - 3 < w.)
    if (!(x + N <= vend && 2 * x + 4 * N - 2 <= w)) return x;
    F a0 = S::load(src + 2 * x - 2), a1 = S::load(src + 2 * x - 2 + N);
    F e = S::permute2(a0, a1, even), o = S::permute2(a0, a1, odd);
    for (; x + N <= vend && 2 * x + 4 * N - 2 <= w; x += N) {
      const float* p = src + 2 * x - 2 + 2 * N;
      const F b0 = S::load(p), b1 = S::load(p + N);
      const F e1 = S::permute2(b0, b1, even), o1 = S::permute2(b0, b1, odd);
      S::store(row + x,
               down_h_vector<S>(e, o, S::next1(e, e1), S::next1(o, o1), S::permute2(e, e1, two)));
      e = e1;
      o = o1;
    }
  } else {
    (void)src, (void)w, (void)vend, (void)row;
  }
  return x;
}

// Row `src` (w >= 8 floats) filtered and halved into row[0 .. (w + 1) / 2).
void pyr_down_h(const float* src, int w, float* row) {
  using S = Native;
  const int dw = (w + 1) / 2;
  auto px = [&](int i) { return src[i < 0 ? -i : (i >= w ? 2 * w - 2 - i : i)]; };
  auto scalar = [&](int x) {
    const int c = 2 * x;
    return down_scalar(px(c - 2), px(c - 1), px(c), px(c + 1), px(c + 2));
  };
  // OpenCV: column 0 by its scalar code (the left border), then its vector loop from column 1
  // in steps of 4 while inside width0, then the scalar code.
  const int width0 = imin((w - 3) / 2 + 1, dw);
  const int vend = width0 > 1 ? 1 + (width0 - 1) / 4 * 4 : 1;
  row[0] = scalar(0);
  int x = pyr_down_h_vectors<S>(src, w, vend, row);
  for (; x < vend; ++x) {
    const float* p = src + 2 * x;
    row[x] = down_h_vector<Scalar>(p[-2], p[-1], p[0], p[1], p[2]);
  }
  for (; x < dw; ++x)
    row[x] = scalar(x);
}

// Row `dst` (dw floats) from the five filtered rows 2y - 2 .. 2y + 2 (reflected at the borders).
void pyr_down_v(const float* const* rows, int dw, float* dst) {
  using S = Native;
  const float *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3], *r4 = rows[4];
  // OpenCV's vector loop covers the columns below dw / 4 * 4.
  const int vend = dw / 4 * 4;
  int x = 0;
  for (; x + S::N <= vend; x += S::N) {
    S::store(dst + x, down_v_vector<S>(S::load(r0 + x), S::load(r1 + x), S::load(r2 + x),
                                       S::load(r3 + x), S::load(r4 + x)));
  }
  for (; x < vend; ++x)
    dst[x] = down_v_vector<Scalar>(r0[x], r1[x], r2[x], r3[x], r4[x]);
  for (; x < dw; ++x)
    dst[x] = down_scalar(r0[x], r1[x], r2[x], r3[x], r4[x]) * (1.f / 256.f);
}

}  // namespace
}  // namespace roiflow::flow::detail
