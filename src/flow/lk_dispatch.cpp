// Run-time choice of the dense LK kernels (lk_kernels.hpp).
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
