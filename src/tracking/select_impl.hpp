// Internal to src/tracking: selection of the k-th smallest of a few hundred floats (the medians a
// tracker takes of its pixels' flow, texture and errors every frame), by branch-free partitions.
//
//   // inside src/tracking only
//   #include "tracking/select_impl.hpp"
//   std::vector<float> v{3.f, 1.f, 2.f};
//   const float m = roiflow::tracking::detail::kth_smallest(v.data(), v.size(), 1);  // 2
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace roiflow::tracking::detail {

// The value std::nth_element puts at rank k of a[0, n) (k < n), found by three-way partitions
// around a median of three; overwrites a (the values it holds afterwards are not all the input's).
// Equal to nth_element's (up to the sign of a zero), several times faster on the few hundred
// values of a tracker's medians: a partition writes every value to both sides and advances one
// (no branch to mispredict), 16 values at a time with AVX-512. `spare` holds n floats. NaN has no
// rank: with one among them, this is nth_element's own answer.
inline float kth_smallest(float* a, std::size_t n, std::size_t k, float* spare) {
  if (std::any_of(a, a + n, [](float x) { return x != x; })) {
    std::nth_element(a, a + k, a + n);
    return a[k];
  }
  for (int depth = 0; n > 16 && depth < 64; ++depth) {
    const float x0 = a[0], x1 = a[n / 2], x2 = a[n - 1];
    const float p = std::max(std::min(x0, x1), std::min(std::max(x0, x1), x2));
    // Below p to the front of a (each value is read before its place is written), the rest to
    // spare.
    std::size_t below = 0, rest = 0, i = 0;
#if defined(__AVX512F__)
    const __m512 vp = _mm512_set1_ps(p);
    for (; i + 16 <= n; i += 16) {
      const __m512 x = _mm512_loadu_ps(a + i);
      const __mmask16 lt = _mm512_cmp_ps_mask(x, vp, _CMP_LT_OQ);
      _mm512_storeu_ps(a + below, _mm512_maskz_compress_ps(lt, x));
      _mm512_storeu_ps(spare + rest, _mm512_maskz_compress_ps(static_cast<__mmask16>(~lt), x));
      const auto count = static_cast<std::size_t>(__builtin_popcount(lt));
      below += count;
      rest += 16 - count;
    }
#endif
    for (; i < n; ++i) {
      const float x = a[i];
      const bool lt = x < p;
      a[below] = x;
      spare[rest] = x;
      below += static_cast<std::size_t>(lt);
      rest += static_cast<std::size_t>(!lt);
    }
    if (k < below) {
      n = below;
      continue;
    }
    // Of the rest, those above p go to a (no longer needed), the others equal p.
    std::size_t above = 0;
    i = 0;
#if defined(__AVX512F__)
    for (; i + 16 <= rest; i += 16) {
      const __m512 x = _mm512_loadu_ps(spare + i);
      const __mmask16 gt = _mm512_cmp_ps_mask(vp, x, _CMP_LT_OQ);
      _mm512_storeu_ps(a + above, _mm512_maskz_compress_ps(gt, x));
      above += static_cast<std::size_t>(__builtin_popcount(gt));
    }
#endif
    for (; i < rest; ++i) {
      const float x = spare[i];
      a[above] = x;
      above += static_cast<std::size_t>(p < x);
    }
    const std::size_t equal = rest - above;
    if (k < below + equal) return p;
    k -= below + equal;
    n = above;
  }
  std::nth_element(a, a + k, a + n);
  return a[k];
}

// kth_smallest with its own spare room.
inline float kth_smallest(float* a, std::size_t n, std::size_t k) {
  constexpr std::size_t kOnStack = 2048;
  if (n <= kOnStack) {
    float spare[kOnStack];
    return kth_smallest(a, n, k, spare);
  }
  std::vector<float> spare(n);
  return kth_smallest(a, n, k, spare.data());
}

// The median (the element of rank size / 2) of `v`, which must not be empty; overwrites `v`.
inline float median(std::vector<float>& v) {
  return kth_smallest(v.data(), v.size(), v.size() / 2);
}

}  // namespace roiflow::tracking::detail
