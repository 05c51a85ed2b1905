// Multi-object benchmarks on the synthetic traffic scene (eval::TrafficScene).
//
//   BM_TrafficRender/<N>/<W>x<H>      rendering one frame of the scene with N vehicles (the
//                                     cost a synthetic:...:N input adds to the source stage)
//
//   build/release/bench/mot_bench --benchmark_filter=TrafficRender
#include <benchmark/benchmark.h>

#include <string>

#include "eval/traffic_scene.hpp"

namespace {

using namespace roiflow;

void bm_traffic_render(benchmark::State& state, int objects, cv::Size size) {
  eval::TrafficSceneParams p;
  p.size = size;
  p.frames = 1'000'000;
  p.objects = objects;
  const eval::TrafficScene scene(p);
  long long i = 0;
  for (auto _ : state) {
    cv::Mat frame = scene.render(i++ % 1000);
    benchmark::DoNotOptimize(frame.data);
  }
  state.SetItemsProcessed(state.iterations());
}

const int kRegistered = [] {
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 720)}) {
    for (const int n : {1, 4, 16, 64}) {
      const std::string name = "BM_TrafficRender/" + std::to_string(n) + "/" +
                               std::to_string(size.width) + "x" + std::to_string(size.height);
      benchmark::RegisterBenchmark(name.c_str(), bm_traffic_render, n, size)
          ->Unit(benchmark::kMillisecond);
    }
  }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
