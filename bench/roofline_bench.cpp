// The machine's roofline on one thread: the peak of fused multiply-adds of the widest vectors
// this build's flow kernels use, and the bandwidth of a triad (a = b + s c) whose arrays fit the
// first-level cache, the second-level cache, or only main memory. docs/PERFORMANCE.md holds dense
// LK's bytes and FLOPs per pixel against these figures.
//
//   build/release/bench/roofline_bench --benchmark_repetitions=5
//     --benchmark_report_aggregates_only=true
//
//   BM_PeakFma                  counter GFLOP/s (a fused multiply-add counts 2)
//   BM_Triad/<bytes of arrays>  counter GB/s (three arrays read or written per element)
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstring>
#include <vector>

#include "flow/simd.hpp"

namespace {

using roiflow::flow::simd::Native;

void bm_peak_fma(benchmark::State& state) {
  using F = Native::F;
  // Twelve independent chains hide the FMA latency on every core of the last decade.
  constexpr int kChains = 12;
  constexpr int kSteps = 1 << 12;
  F acc[kChains];
  for (int c = 0; c < kChains; ++c)
    acc[c] = Native::set1(1.f + 1e-3f * static_cast<float>(c));
  const F a = Native::set1(0.999999f), b = Native::set1(1e-7f);
  for (auto _ : state) {
    for (int i = 0; i < kSteps; ++i) {
      for (int c = 0; c < kChains; ++c)
        acc[c] = Native::madd(acc[c], a, b);
    }
    for (int c = 0; c < kChains; ++c)
      benchmark::DoNotOptimize(acc[c]);
  }
  const double flops = 2.0 * Native::N * kChains * kSteps;
  state.counters["GFLOP/s"] = benchmark::Counter(flops * static_cast<double>(state.iterations()) /
                                                     1e9,
                                                 benchmark::Counter::kIsRate);
  state.SetLabel(roiflow::flow::simd::kNativeName);
}

void bm_triad(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0)) / (3 * sizeof(float));
  const std::size_t count = n / Native::N * Native::N;
  std::vector<float> a(count + Native::N), b(count + Native::N, 1.f), c(count + Native::N, 2.f);
  const Native::F s = Native::set1(0.5f);
  for (auto _ : state) {
    for (std::size_t i = 0; i < count; i += Native::N)
      Native::store(a.data() + i, Native::madd(s, Native::load(c.data() + i),
                                               Native::load(b.data() + i)));
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  const double bytes = 3.0 * sizeof(float) * static_cast<double>(count);
  state.counters["GB/s"] = benchmark::Counter(bytes * static_cast<double>(state.iterations()) / 1e9,
                                              benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(bm_peak_fma)->Name("BM_PeakFma");
// 24 KiB: half the first-level cache; 1 MiB: half a second-level cache of 2 MiB; 1 GiB: memory.
BENCHMARK(bm_triad)->Name("BM_Triad")->Arg(24 << 10)->Arg(1 << 20)->Arg(1 << 30);

BENCHMARK_MAIN();
