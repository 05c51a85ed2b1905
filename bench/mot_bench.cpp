// Multi-object benchmarks on the synthetic traffic scene (eval::TrafficScene).
//
//   BM_TrackObjects/<N>/<W>x<H>/threads:<t>   pipeline::track_objects (every moving object, no
//                                     sink) over kFrames frames of the scene with N vehicles,
//                                     rendered beforehand (the time is the tracking graph's,
//                                     decoding excluded); counters: fps (frames per second of
//                                     wall time), mota and idf1 of that run against the scene's
//                                     boxes. N in {1, 4, 16, 64}, 640x480 and 1280x720, 1 and 2
//                                     threads (and 4, 8, 16 where the machine has them).
//   BM_TrafficRender/<N>/<W>x<H>      rendering one frame of the scene with N vehicles (the
//                                     cost a synthetic:...:N input adds to the source stage)
//
//   build/release/bench/mot_bench --benchmark_filter=TrackObjects/16/640x480
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "eval/mot.hpp"
#include "eval/traffic_scene.hpp"
#include "pipeline/mot_run.hpp"

namespace {

using namespace roiflow;

constexpr int kFrames = 120;

// The frames of one (N, size), rendered once and kept while that benchmark family runs.
struct Clip {
  int objects = 0;
  cv::Size size;
  std::vector<roiflow::video::Frame> frames;
  std::vector<roiflow::eval::MotBox> truth;
};

const Clip& clip(int objects, cv::Size size) {
  static std::unique_ptr<Clip> cached;
  if (cached && cached->objects == objects && cached->size == size) return *cached;
  cached.reset();
  auto c = std::make_unique<Clip>();
  c->objects = objects;
  c->size = size;
  eval::TrafficSceneParams p;
  p.size = size;
  p.frames = kFrames;
  p.objects = objects;
  const eval::TrafficScene scene(p);
  for (int i = 0; i < kFrames; ++i) {
    video::Frame f;
    f.index = i;
    f.timestamp_s = i / 25.0;
    f.image = scene.render(i);
    cv::cvtColor(f.image, f.gray, cv::COLOR_BGR2GRAY);
    c->frames.push_back(f);
  }
  c->truth = scene.ground_truth();
  cached = std::move(c);
  return *cached;
}

void bm_track_objects(benchmark::State& state, int objects, cv::Size size, int threads) {
  const Clip& c = clip(objects, size);
  double wall_s = 0;
  std::vector<eval::MotBox> output;
  for (auto _ : state) {
    std::size_t next = 0;
    output.clear();
    pipeline::MotRunOptions o;
    o.threads = threads;
    o.on_frame = [&](const pipeline::MotTrackedFrame& f) {
      for (const tracking::MotObject& t : f.output->objects) {
        if (t.lost) continue;
        eval::MotBox b;
        b.frame = static_cast<int>(f.output->index) + 1;
        b.id = static_cast<int>(t.id);
        b.box = cv::Rect2d(t.box.x + 1.0, t.box.y + 1.0, t.box.width, t.box.height);
        output.push_back(b);
      }
    };
    const pipeline::MotRun run = pipeline::track_objects(
        [&]() -> std::optional<video::Frame> {
          if (next >= c.frames.size()) return std::nullopt;
          return c.frames[next++];
        },
        size, 25.0, o);
    wall_s += run.report.wall_s;
    state.SetIterationTime(run.report.wall_s);
  }
  const double frames = static_cast<double>(state.iterations()) * kFrames;
  state.counters["fps"] = wall_s > 0 ? frames / wall_s : 0.0;
  const eval::MotScore s = eval::score_mot(output, c.truth);
  state.counters["mota"] = s.mota;
  state.counters["idf1"] = s.idf1;
  state.SetItemsProcessed(static_cast<long long>(frames));
}

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
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 720)}) {
    for (const int n : {1, 4, 16, 64}) {
      for (const int t : {1, 2, 4, 8, 16}) {
        if (t > 2 && t > cores) continue;
        const std::string name = "BM_TrackObjects/" + std::to_string(n) + "/" +
                                 std::to_string(size.width) + "x" + std::to_string(size.height) +
                                 "/threads:" + std::to_string(t);
        benchmark::RegisterBenchmark(name.c_str(), bm_track_objects, n, size, t)
            ->Unit(benchmark::kMillisecond)
            ->UseManualTime();
      }
    }
  }
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
