// Dense flow, roiflow against OpenCV's dense methods on the same synthetic frames. One binary,
// so speed ratios come from one run, next to each method's endpoint error.
//
//   build/release/bench/flow_bench --benchmark_filter=640x480
//
//   BM_Flow/<method>/<W>x<H>/threads:<n>   method: roiflow_paper, roiflow_accurate, roiflow_fast,
//                                          roiflow_paper_l4i1, roiflow_paper_l4i1r,
//                                          roiflow_paper_l4f1r (variants of paper, see
//                                          docs/PERFORMANCE.md), dis_ultrafast, dis_fast,
//                                          dis_medium, farneback
//   BM_TwoThreadBound/<paper|fast|accurate>/<W>x<H>  one pair's two-thread schedule timed on the
//   CPU clock
//                                          of one thread: speedup2, what two idle cores would give
//   BM_Pyramid/<W>x<H>                     build_pyramid(frame) alone (paper preset), 1 thread
//   BM_Pretreatment/<roiflow|opencv>/<W>x<H>  level 0 alone (sigma 0.5): roiflow's fused pass vs
//                                          OpenCV's convertTo + GaussianBlur, 1 thread
//   BM_Dataset/<dataset>/<method>/threads:1  with ROIFLOW_DATA=ROOT (e.g. ../shared/data): one
//                                          per evaluation tree under ROOT (middlebury, kitti,
//                                          sintel, flyingchairs; partial trees as `roiflow eval`
//                                          reads them), every pair per iteration; counters EPE,
//                                          AAE and Fl are the means over pairs (Sintel's invalid
//                                          pixels not scored), ms_per_pair the time, pairs the
//                                          count. ROIFLOW_MIDDLEBURY=DIR adds DIR as "middlebury".
//
// Every benchmark runs inside run_with_threads(n): n arena slots for roiflow's stripes and
// cv::setNumThreads(n) for OpenCV's own loops (DIS, Farneback, and the remap/pyrDown roiflow
// calls). Times are wall-clock ("/real_time" in the reported names): CPU time of the main thread
// would hide the work done by the others. Counters: Mpix/s, frame pixels per wall-clock second;
// EPE, mean endpoint error in pixels against the ground truth, measured on the last flow of the
// timing loop. Frames: make_scene(MovingObject), built once per size on first use.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "eval/flow_eval.hpp"
#include "eval/synthetic.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "flow/pyramid.hpp"
#include "pipeline/tbb_executor.hpp"

namespace {

using roiflow::eval::Scene;

constexpr std::uint64_t kSeed = 1;
const cv::Size kSizes[] = {{640, 480}, {1280, 720}};
constexpr int kThreadCounts[] = {1, 2};

const Scene& scene_of(cv::Size size) {
  // Benchmarks run one after another on the main thread, so the cache needs no lock.
  static std::map<std::pair<int, int>, Scene> scenes;
  auto [it, inserted] = scenes.try_emplace({size.width, size.height});
  if (inserted)
    it->second = roiflow::eval::make_scene(roiflow::eval::SceneKind::MovingObject, size, kSeed);
  return it->second;
}

std::string size_name(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

void set_rate(benchmark::State& state, cv::Size size) {
  state.counters["Mpix/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * size.area() / 1e6, benchmark::Counter::kIsRate);
}

// Writes the CV_32FC2 flow from frame0 to frame1 of the scene.
using FlowFn = std::function<void(const Scene&, cv::Mat&)>;

struct Method {
  const char* name;
  // Called once per benchmark run, outside the timing loop, so per-instance set-up (DIS's
  // buffers) is not timed.
  std::function<FlowFn()> make;
};

FlowFn roiflow_flow(const roiflow::flow::LkParams& params) {
  // Stateless, and it runs in whichever arena run_with_threads set up: one serves every run.
  static const roiflow::pipeline::TbbExecutor executor;
  // The OpenCV interface, as a DIS user would swap it in: one object keeps its workspace and
  // writes into the caller's flow buffer, as DIS's calc() does, so neither side pays for fresh
  // pages on every call.
  cv::Ptr<cv::DenseOpticalFlow> lk = roiflow::flow::createDenseLK(params, &executor);
  return [lk](const Scene& s, cv::Mat& flow) { lk->calc(s.frame0, s.frame1, flow); };
}

FlowFn dis_flow(int preset) {
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(preset);
  return [dis](const Scene& s, cv::Mat& flow) {
    // DIS takes a flow argument of the frames' size as its initial flow: handing it back the
    // flow of the previous call on the same pair (as a timing loop does) would start it from a
    // converged answer. A fresh output makes every call compute from scratch, as roiflow's do.
    cv::Mat out;
    dis->calc(s.frame0, s.frame1, out);
    flow = out;
  };
}

FlowFn farneback_flow() {
  return [](const Scene& s, cv::Mat& flow) {
    // OpenCV's sample parameters (samples/cpp/fback.cpp).
    cv::calcOpticalFlowFarneback(s.frame0, s.frame1, flow, 0.5, 3, 15, 3, 5, 1.2, 0);
  };
}

// paper with `levels`, `finest_iterations`, `finest_level`; robust_scale > 0 also masks the
// samples outside the frame.
roiflow::flow::LkParams paper_variant(int levels, int finest_iterations, int finest_level,
                                      double robust_scale) {
  roiflow::flow::LkParams p = roiflow::flow::LkParams::paper();
  p.levels = levels;
  p.finest_iterations = finest_iterations;
  p.finest_level = finest_level;
  p.robust_scale = robust_scale;
  p.mask_outside = robust_scale > 0;
  return p;
}

const std::vector<Method>& methods() {
  static const std::vector<Method> all = {
      {"roiflow_paper", [] { return roiflow_flow(roiflow::flow::LkParams::paper()); }},
      {"roiflow_accurate", [] { return roiflow_flow(roiflow::flow::LkParams::accurate()); }},
      {"roiflow_fast", [] { return roiflow_flow(roiflow::flow::LkParams::fast()); }},
      // Cheaper variants of paper (docs/PERFORMANCE.md): a 4-level pyramid with 1 iteration at
      // level 0 (3 on the others); the same with samples outside the frame masked and Cauchy
      // weights (r); the paper's 3 levels x 3 iterations on levels 3..1 with level 0 upsampled,
      // masked and weighted.
      {"roiflow_paper_l4i1", [] { return roiflow_flow(paper_variant(4, 1, 0, 0.0)); }},
      {"roiflow_paper_l4i1r", [] { return roiflow_flow(paper_variant(4, 1, 0, 0.04)); }},
      {"roiflow_paper_l4f1r", [] { return roiflow_flow(paper_variant(4, 0, 1, 0.02)); }},
      {"dis_ultrafast", [] { return dis_flow(cv::DISOpticalFlow::PRESET_ULTRAFAST); }},
      {"dis_fast", [] { return dis_flow(cv::DISOpticalFlow::PRESET_FAST); }},
      {"dis_medium", [] { return dis_flow(cv::DISOpticalFlow::PRESET_MEDIUM); }},
      {"farneback", farneback_flow},
  };
  return all;
}

void bm_flow(benchmark::State& state, const Method& method, cv::Size size, int threads) {
  const Scene& scene = scene_of(size);
  roiflow::pipeline::run_with_threads(threads, [&] {
    const FlowFn flow_fn = method.make();
    cv::Mat flow;
    // Untimed first call: allocates the output and wakes the arena's workers, which would
    // otherwise be charged to the first timed iteration.
    flow_fn(scene, flow);
    for (auto _ : state) {
      flow_fn(scene, flow);
      benchmark::DoNotOptimize(flow.data);
      benchmark::ClobberMemory();
    }
    set_rate(state, size);
    state.counters["EPE"] = roiflow::flow::flow_errors(flow, scene.flow).epe;
  });
}

void bm_pyramid(benchmark::State& state, cv::Size size) {
  const Scene& scene = scene_of(size);
  roiflow::pipeline::run_with_threads(1, [&] {
    for (auto _ : state) {
      const roiflow::flow::LkParams paper = roiflow::flow::LkParams::paper();
      roiflow::flow::Pyramid pyr =
          roiflow::flow::build_pyramid(scene.frame0, paper.levels, paper.sigma);
      benchmark::DoNotOptimize(pyr.levels.data());
    }
    set_rate(state, size);
  });
}

// The pretreatment alone, roiflow's (level 0 of build_pyramid) beside OpenCV's conversion and
// GaussianBlur, which compute the same: the peer of the fused pass in flow/pyramid.cpp.
void bm_pretreatment(benchmark::State& state, cv::Size size, bool opencv) {
  const Scene& scene = scene_of(size);
  const double sigma = roiflow::flow::LkParams::paper().sigma;
  roiflow::pipeline::run_with_threads(1, [&] {
    roiflow::flow::Pyramid pyr;
    cv::Mat unit, smooth;
    for (auto _ : state) {
      if (opencv) {
        scene.frame0.convertTo(unit, CV_32F, 1.0 / 255.0);
        cv::GaussianBlur(unit, smooth, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
        benchmark::DoNotOptimize(smooth.data);
      } else {
        roiflow::flow::build_pyramid(scene.frame0, 1, sigma, pyr);
        benchmark::DoNotOptimize(pyr.levels[0].data);
      }
    }
    set_rate(state, size);
  });
}

// The two-thread schedule of one pair, run on one thread and timed on its CPU clock, so that a
// loaded machine (other processes on the cores) cannot blur it: every for_range region of a
// `lanes`-thread executor (the two pyramids, the row bands of each level, the result copy) runs
// its chunks one after the other, and the region is charged what `lanes` threads would take at
// best, max(longest chunk, sum / lanes); the serial rest is charged as it is. Sync and memory
// contention between the threads are not in it: it is the bound a quiet machine approaches.
class CriticalPathExecutor final : public roiflow::Executor {
 public:
  explicit CriticalPathExecutor(int lanes) : lanes_(lanes) {}
  void for_range(int begin, int end, int grain,
                 const std::function<void(int, int)>& body) const override {
    const int step = std::max(1, grain);
    double sum = 0, longest = 0;
    for (int b = begin; b < end; b += step) {
      const double t0 = thread_cpu_s();
      body(b, std::min(end, b + step));
      const double t = thread_cpu_s() - t0;
      sum += t;
      longest = std::max(longest, t);
    }
    saved_s_ += sum - std::max(longest, sum / lanes_);
    inside_s_ += sum;
    uneven_s_ += std::max(longest, sum / lanes_) - sum / lanes_;
  }
  int concurrency() const override { return lanes_; }
  // CPU seconds the schedule would not take on `lanes` threads, since the last reset.
  double saved_s() const { return saved_s_; }
  // CPU seconds inside the parallel regions, and what their uneven chunks add to the schedule
  // beyond an even split, since the last reset.
  double inside_s() const { return inside_s_; }
  double uneven_s() const { return uneven_s_; }
  void reset() { saved_s_ = inside_s_ = uneven_s_ = 0; }

  static double thread_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }

 private:
  int lanes_;
  mutable double saved_s_ = 0;
  mutable double inside_s_ = 0;
  mutable double uneven_s_ = 0;
};

// BM_TwoThreadBound/<preset>/<W>x<H>: counters t1_ms (one pair on one thread, CPU time),
// work2_ms (the two-thread schedule's total CPU time: its bands recompute some rows),
// critical2_ms (what two threads would take, see CriticalPathExecutor) and speedup2 = t1_ms /
// critical2_ms; critical2_ms = serial2_ms (the work outside the parallel regions) + half of the
// work inside them + uneven2_ms (what their chunks' imbalance adds).
void bm_two_thread_bound(benchmark::State& state, roiflow::flow::LkParams params, cv::Size size) {
  const Scene& scene = scene_of(size);
  roiflow::pipeline::run_with_threads(1, [&] {
    CriticalPathExecutor two(2);
    roiflow::flow::DenseLK serial(params), split(params, &two);
    roiflow::flow::FlowResult a, b;
    serial.calc(scene.frame0, scene.frame1, a);
    split.calc(scene.frame0, scene.frame1, b);
    double t1 = 0, work2 = 0, critical2 = 0, serial2 = 0, uneven2 = 0;
    for (auto _ : state) {
      double t0 = CriticalPathExecutor::thread_cpu_s();
      serial.calc(scene.frame0, scene.frame1, a);
      t1 += CriticalPathExecutor::thread_cpu_s() - t0;
      two.reset();
      t0 = CriticalPathExecutor::thread_cpu_s();
      split.calc(scene.frame0, scene.frame1, b);
      const double w = CriticalPathExecutor::thread_cpu_s() - t0;
      work2 += w;
      critical2 += w - two.saved_s();
      serial2 += w - two.inside_s();
      uneven2 += two.uneven_s();
    }
    if (cv::norm(a.flow, b.flow, cv::NORM_INF) != 0.0) state.SkipWithError("flows differ");
    const double n = static_cast<double>(state.iterations());
    state.counters["t1_ms"] = 1e3 * t1 / n;
    state.counters["work2_ms"] = 1e3 * work2 / n;
    state.counters["critical2_ms"] = 1e3 * critical2 / n;
    state.counters["speedup2"] = t1 / critical2;
    state.counters["serial2_ms"] = 1e3 * serial2 / n;
    state.counters["uneven2_ms"] = 1e3 * uneven2 / n;
  });
}

// Real data with ground truth: a dataset's pairs as scenes (frames, ground-truth flow), with the
// pixels its tree says not to score (Sintel's invalid masks), as `roiflow eval` reads them.
struct Dataset {
  std::string name;
  std::vector<Scene> scenes;
  std::vector<cv::Mat> excluded;  // empty Mat = score every pixel with a ground truth
};

Dataset load_dataset(const std::string& name, const std::string& dir) {
  Dataset data{name, {}, {}};
  std::vector<std::string> skipped;
  for (const roiflow::eval::EvalPair& pair : roiflow::eval::find_pairs(dir, {}, &skipped)) {
    data.scenes.push_back({roiflow::eval::read_gray(pair.frame0),
                           roiflow::eval::read_gray(pair.frame1),
                           roiflow::eval::read_flow_ground_truth(pair.ground_truth)});
    data.excluded.push_back(
        pair.exclude_mask.empty() ? cv::Mat() : roiflow::eval::read_gray(pair.exclude_mask));
  }
  if (!skipped.empty()) {
    std::fprintf(stderr, "flow_bench: %s: %s\n", name.c_str(),
                 roiflow::eval::skipped_line(skipped).c_str());
  }
  return data;
}

// Every evaluation tree directly under `root` (middlebury, kitti, sintel, flyingchairs, ...),
// sorted by name; folders that hold none (tracking videos, ...) are left out.
std::vector<Dataset> load_datasets(const std::string& root) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    if (!entry.is_directory()) continue;
    try {
      roiflow::eval::detect_layout(entry.path().string());
      names.push_back(entry.path().filename().string());
    } catch (const roiflow::Error&) {  // not an evaluation tree
    }
  }
  if (ec) throw roiflow::Error("cannot list '" + root + "': " + ec.message());
  std::sort(names.begin(), names.end());
  std::vector<Dataset> out;
  for (const std::string& name : names)
    out.push_back(load_dataset(name, (std::filesystem::path(root) / name).string()));
  return out;
}

void bm_dataset(benchmark::State& state, const Method& method, const Dataset* data) {
  roiflow::pipeline::run_with_threads(1, [&] {
    const FlowFn flow_fn = method.make();
    const std::size_t n = data->scenes.size();
    std::vector<cv::Mat> flows(n);
    for (auto _ : state) {
      for (std::size_t i = 0; i < n; ++i)
        flow_fn(data->scenes[i], flows[i]);
      benchmark::ClobberMemory();
    }
    double epe = 0, aae = 0, fl = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const roiflow::flow::FlowErrors e =
          roiflow::flow::flow_errors(flows[i], data->scenes[i].flow, data->excluded[i]);
      epe += e.epe / static_cast<double>(n);
      aae += e.aae_deg / static_cast<double>(n);
      fl += e.fl / static_cast<double>(n);
    }
    state.counters["EPE"] = epe;
    state.counters["AAE"] = aae;
    state.counters["Fl"] = fl;
    state.counters["pairs"] = static_cast<double>(n);
    state.counters["ms_per_pair"] =
        benchmark::Counter(static_cast<double>(state.iterations() * n) / 1e3,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  });
}

void register_benchmarks() {
  static std::vector<Dataset> datasets;
  if (const char* root = std::getenv("ROIFLOW_DATA")) datasets = load_datasets(root);
  if (const char* dir = std::getenv("ROIFLOW_MIDDLEBURY")) {
    datasets.push_back(load_dataset("middlebury", dir));
  }
  for (const Dataset& data : datasets) {
    for (const Method& method : methods()) {
      benchmark::RegisterBenchmark(
          ("BM_Dataset/" + data.name + "/" + method.name + "/threads:1").c_str(), bm_dataset,
          method, &data)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(3);
    }
  }
  for (const cv::Size size : kSizes) {
    for (const Method& method : methods()) {
      for (const int threads : kThreadCounts) {
        const std::string name = "BM_Flow/" + std::string(method.name) + "/" + size_name(size) +
                                 "/threads:" + std::to_string(threads);
        benchmark::RegisterBenchmark(name.c_str(), bm_flow, method, size, threads)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
    for (const char* preset : {"paper", "fast", "accurate"}) {
      benchmark::RegisterBenchmark(
          ("BM_TwoThreadBound/" + std::string(preset) + "/" + size_name(size)).c_str(),
          bm_two_thread_bound, roiflow::flow::LkParams::preset(preset), size)
          ->Unit(benchmark::kMillisecond);
    }
    benchmark::RegisterBenchmark(("BM_Pyramid/" + size_name(size)).c_str(), bm_pyramid, size)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    for (const bool opencv : {false, true}) {
      const std::string name =
          std::string("BM_Pretreatment/") + (opencv ? "opencv" : "roiflow") + "/" + size_name(size);
      benchmark::RegisterBenchmark(name.c_str(), bm_pretreatment, size, opencv)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_benchmarks();
  // The default minimum time goes in as the first flag so that a --benchmark_min_time on the
  // command line still wins; Benchmark::MinTime() would override the command line and add
  // "/min_time:" to every name.
  std::string default_min_time = "--benchmark_min_time=0.5";
  std::vector<char*> args(argv, argv + argc);
  args.insert(args.begin() + 1, default_min_time.data());
  int args_count = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&args_count, args.data());
  if (benchmark::ReportUnrecognizedArguments(args_count, args.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
