// Run-time choice of the dense LK kernels (lk_kernels.hpp).
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>

#include "flow/lk_kernels.hpp"

namespace roiflow::flow::detail {

extern const LkKernels lk_kernels_base;
#ifdef ROIFLOW_HAVE_AVX2_KERNELS
extern const LkKernels lk_kernels_avx2;
#endif
#ifdef ROIFLOW_HAVE_AVX512_KERNELS
extern const LkKernels lk_kernels_avx512;
#endif

namespace {

std::atomic<const LkKernels*> forced{nullptr};

const LkKernels& choose() {
  const LkKernels* kinds[4];
  const int n = available_lk_kernels(kinds, 4);
  if (const char* want = std::getenv("ROIFLOW_SIMD")) {
    for (int i = 0; i < n; ++i) {
      if (std::strcmp(want, kinds[i]->name) == 0 ||
          (std::strcmp(want, "base") == 0 && kinds[i] == &lk_kernels_base)) {
        return *kinds[i];
      }
    }
  }
  return *kinds[0];
}

}  // namespace

int reach_up(const LevelJob& level) {
  return -level.lo + (level.derivative == 0 ? 0 : 1);
}

int reach_down(const LevelJob& level) {
  return level.hi + 1;
}

RowSpan shared_rows(const LevelJob& level, int iterations, int split, int k) {
  if (split <= 0 || k < 0 || k + 1 >= iterations) return {};
  // The band starting at `split` starts iteration i on the stripe before the rows iteration
  // i + 1 reads (lk_band_impl.hpp's iteration_rows) and solves iteration k from the first row
  // iteration k + 1 reads; the band ending at `split` runs iteration k reach_down rows further
  // down for each later iteration.
  int next = split;  // where the lower band starts iteration i + 1
  for (int i = iterations - 2; i > k; --i) {
    const int v = next - reach_up(level);
    const int s = level.stripe;
    next = std::max(0, v >= 0 ? v / s * s : -((-v + s - 1) / s) * s);
  }
  const int first = std::max(0, next - reach_up(level));
  const int last = std::min(level.h, split + (iterations - 1 - k) * reach_down(level));
  return {first, std::max(0, last - first)};
}

int available_lk_kernels(const LkKernels** out, int capacity) {
  int n = 0;
  auto add = [&](const LkKernels* k) {
    if (n < capacity) out[n++] = k;
  };
#if defined(ROIFLOW_HAVE_AVX512_KERNELS) && (defined(__x86_64__) || defined(__i386__))
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq")) {
    add(&lk_kernels_avx512);
  }
#endif
#if defined(ROIFLOW_HAVE_AVX2_KERNELS) && (defined(__x86_64__) || defined(__i386__))
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) add(&lk_kernels_avx2);
#endif
  add(&lk_kernels_base);
  return n;
}

const LkKernels& lk_kernels() {
  if (const LkKernels* k = forced.load(std::memory_order_acquire)) return *k;
  static const LkKernels& chosen = choose();
  return chosen;
}

void set_lk_kernels_for_testing(const LkKernels* kernels) {
  forced.store(kernels, std::memory_order_release);
}

}  // namespace roiflow::flow::detail
