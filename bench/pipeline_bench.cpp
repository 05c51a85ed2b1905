// The whole pipeline on video files: decode-only ceiling, tracking in local and global mode,
// dense mode, each at 1 and 2 threads, in one binary so that ratios come from one run.
//
//   build/release/bench/pipeline_bench                       # the synthetic 640x480 video
//   ROIFLOW_VIDEOS=../shared/data/video build/release/bench/pipeline_bench
//
//   BM_Decode/<video>                       VideoSource alone (FFmpeg through VideoDecoder, BGR
//                                           and gray): the ceiling of any pipeline
//   BM_DecodeGray/<video>                   the same with colour deferred and never asked for
//                                           (gray only): the ceiling of a pipeline that needs no
//                                           colour, as tracking without a video sink mostly does
//   BM_DecodeOpenCV/<video>                 cv::VideoCapture::read + cvtColor to gray, what a
//                                           plain OpenCV program pays (VideoSource before it
//                                           had its own decoder)
//   BM_Track/<video>/<local|global>/threads:<n>   run_tracking, no sinks; the target is found
//                                           by the global treatment (no --init)
//   BM_Dense/<video>/threads:<n>            run_dense (paper preset), no sinks
//
// <video> is synthetic640x480 (300 frames of the demo's TrackingScene, written once as MPEG-4
// to the temp dir), with ROIFLOW_BENCH_HD=1 synthetic1920x1080_h264 (the same scene at 1920x1080
// as H.264, written once, ~30 s), and with ROIFLOW_VIDEOS=DIR every .avi/.mp4/.mkv in DIR. One
// iteration processes the whole file. Counters: fps, frames per wall-clock second of the whole run
// (decode included); tracker_fps, frames per second of the tracker's own busy time (pyramid +
// LK + decision: decode excluded), global_activations.
//
//   BM_TrackVsDecode/<video>/local/threads:2   five decode-only passes and five local-mode
//                                           runs, alternating; counters decode_fps, track_fps
//                                           (medians), vs_decode (median of the rounds'
//                                           ratios): the "tracking vs decode-only" bar, and
//                                           decode_cores / track_cores (process CPU time over
//                                           wall time: how busy the machine was); also
//                                           opencv_decode_fps and vs_opencv_decode, the same
//                                           against BM_DecodeOpenCV's way of decoding, and
//                                           gray_decode_fps / vs_gray_decode against
//                                           BM_DecodeGray's. Tracking reads its input as the
//                                           CLI does (VideoSourceParams::defer_colour)
//   BM_GraphOnly/<video>/threads:2          run_tracking with a step that does nothing (five
//                                           repetitions), input read as the CLI does: what the
//                                           graph itself costs over BM_DecodeGray, the ceiling
//                                           of any tracking run
//   BM_TrackerOnly/<video>                  the tracker alone (default params, no executor) on
//                                           the frames decoded once into memory, five
//                                           repetitions (median and min): ms_per_frame over all
//                                           frames, local_ms_per_frame over those the local
//                                           treatment kept (its background refresh included,
//                                           which a pipeline runs beside the frames): the serial
//                                           step that bounds tracking's frames/s at 2 threads
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "eval/tracking_scene.hpp"
#include "pipeline/frame_graph.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/run_stats.hpp"
#include "tracking/tracker.hpp"
#include "video/video_sink.hpp"
#include "video/video_source.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;

constexpr int kThreadCounts[] = {1, 2};

std::string synthetic_video() {
  const fs::path path = fs::temp_directory_path() / "roiflow_bench_synthetic640x480.mp4";
  if (!fs::exists(path)) {
    eval::TrackingSceneParams params;
    params.frames = 300;
    const eval::TrackingScene scene(params);
    video::VideoSink sink(path.string(), 25.0, scene.size());
    for (int i = 0; i < scene.frames(); ++i)
      sink.write(scene.render(i));
    sink.close();
  }
  return path.string();
}

// The same scene at 1920x1080 as H.264 (ROIFLOW_BENCH_HD=1), written once; empty when this
// FFmpeg has no H.264 encoder.
std::string synthetic_hd_video() {
  const fs::path path = fs::temp_directory_path() / "roiflow_bench_synthetic1920x1080_h264.mp4";
  if (!fs::exists(path)) {
    const fs::path partial = path.string() + ".partial.mp4";
    video::VideoSource scene("synthetic:300:1920x1080");
    cv::VideoWriter writer(partial.string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('a', 'v', 'c', '1'), 25, scene.size());
    if (!writer.isOpened()) return {};
    while (auto f = scene.next())
      writer.write(f->image);
    writer.release();
    fs::rename(partial, path);
  }
  return path.string();
}

double ms_total(const nlohmann::ordered_json& stats, const char* stage) {
  const auto& stages = stats.at("stages");
  return stages.contains(stage) ? stages.at(stage).at("ms_total").get<double>() : 0.0;
}

// How the CLI reads a video for tracking and dense mode: colour only when asked for.
video::VideoSourceParams as_the_cli() {
  video::VideoSourceParams params;
  params.defer_colour = true;
  return params;
}

// One decode-only pass over the file read with `params`: its frame count.
long long decode_pass(const std::string& path, const video::VideoSourceParams& params) {
  video::VideoSource source(path, params);
  long long frames = 0;
  while (auto f = source.next()) {
    benchmark::DoNotOptimize(f->image.data);
    benchmark::DoNotOptimize(f->gray.data);
    ++frames;
  }
  return frames;
}

// Every frame as BGR and gray.
long long decode_all(const std::string& path) {
  return decode_pass(path, {});
}

// Colour deferred and never asked for: the gray frames only.
long long decode_all_gray(const std::string& path) {
  return decode_pass(path, as_the_cli());
}

// One decode-only pass with OpenCV's VideoCapture (BGR, then gray): its frame count.
long long decode_all_opencv(const std::string& path) {
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  cv::Mat image, gray;
  long long frames = 0;
  while (capture.read(image)) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
    benchmark::DoNotOptimize(gray.data);
    ++frames;
  }
  return frames;
}

// One tracking run of the file (default params but `mode`), no sinks; `stats` may be null.
pipeline::RunReport track_all(const std::string& path, tracking::TrackMode mode, int threads,
                              report::RunStats* stats, long long* activations = nullptr) {
  video::VideoSource source(path, as_the_cli());
  pipeline::TbbExecutor tiles;
  tracking::TrackerParams params;
  params.mode = mode;
  tracking::Tracker tracker(params, &tiles);
  pipeline::GraphOptions options;
  options.threads = threads;
  options.stats = stats;
  const pipeline::RunReport report =
      pipeline::run_tracking([&] { return source.next(); }, tracker, {}, options);
  if (activations) *activations = tracker.global_activations();
  return report;
}

template <long long (*Decode)(const std::string&)>
void bm_decode(benchmark::State& state, const std::string& path) {
  long long frames = 0;
  for (auto _ : state)
    frames += Decode(path);
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

void bm_track(benchmark::State& state, const std::string& path, tracking::TrackMode mode,
              int threads) {
  long long frames = 0;
  double tracker_ms = 0;
  long long activations = 0;
  for (auto _ : state) {
    report::RunStats stats;
    const pipeline::RunReport report = track_all(path, mode, threads, &stats, &activations);
    frames += report.frames;
    const auto json = stats.to_json(report.wall_s);
    tracker_ms += ms_total(json, "pyramid") + ms_total(json, "track");
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["tracker_fps"] = tracker_ms > 0 ? frames / (tracker_ms / 1000.0) : 0.0;
  state.counters["global_activations"] = static_cast<double>(activations);
}

// CPU time of the whole process (every thread, user + system), seconds.
double process_cpu_s() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

// Frames per second of a decode-only pass and of a local-mode tracking run (2 threads) of the
// same file.
template <long long (*Decode)(const std::string&)>
double decode_fps(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  const long long frames = Decode(path);
  return frames / std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double tracking_fps(const std::string& path, int threads) {
  const pipeline::RunReport report = track_all(path, tracking::TrackMode::Local, threads, nullptr);
  return report.frames / report.wall_s;
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The bar "tracking >= 0.8x the decode-only frames/s" as one figure: decode-only passes and
// tracking runs alternate (kRounds each), so that a drift of the machine's speed, which on a
// shared VM moves single runs by 30 %, moves both alike. vs_decode: the median of the rounds'
// ratios.
void bm_track_vs_decode(benchmark::State& state, const std::string& path, int threads) {
  constexpr int kRounds = 5;
  std::vector<double> decode, track, ratio, decode_cores, track_cores, opencv, opencv_ratio,
      opencv_cores, gray, gray_ratio, gray_cores;
  // Cores kept busy: process CPU time over wall time of a pass.
  auto timed = [](auto&& pass, std::vector<double>& cores) {
    const double cpu0 = process_cpu_s();
    const auto t0 = std::chrono::steady_clock::now();
    const double fps = pass();
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cores.push_back((process_cpu_s() - cpu0) / wall);
    return fps;
  };
  for (auto _ : state) {
    for (int round = 0; round < kRounds; ++round) {
      decode.push_back(timed([&] { return decode_fps<decode_all>(path); }, decode_cores));
      track.push_back(timed([&] { return tracking_fps(path, threads); }, track_cores));
      opencv.push_back(timed([&] { return decode_fps<decode_all_opencv>(path); }, opencv_cores));
      gray.push_back(timed([&] { return decode_fps<decode_all_gray>(path); }, gray_cores));
      ratio.push_back(track.back() / decode.back());
      opencv_ratio.push_back(track.back() / opencv.back());
      gray_ratio.push_back(track.back() / gray.back());
    }
  }
  state.counters["decode_fps"] = median_of(decode);
  state.counters["track_fps"] = median_of(track);
  state.counters["vs_decode"] = median_of(ratio);
  state.counters["decode_cores"] = median_of(decode_cores);
  state.counters["track_cores"] = median_of(track_cores);
  state.counters["opencv_decode_fps"] = median_of(opencv);
  state.counters["vs_opencv_decode"] = median_of(opencv_ratio);
  state.counters["gray_decode_fps"] = median_of(gray);
  state.counters["vs_gray_decode"] = median_of(gray_ratio);
}

// The graph with a tracking step that does nothing: decode, limiter, sequencer and retirement at
// 2 threads, the ceiling of any tracking run through the graph.
void bm_graph_only(benchmark::State& state, const std::string& path) {
  long long frames = 0;
  for (auto _ : state) {
    video::VideoSource source(path, as_the_cli());
    pipeline::TrackStep step;
    step.wants_pyramid = [] { return false; };
    step.process = [](const tracking::TrackerInput& in) {
      tracking::TrackerOutput out;
      out.index = in.index;
      return out;
    };
    pipeline::GraphOptions options;
    options.threads = 2;
    frames += pipeline::run_tracking([&] { return source.next(); }, step, {}, options).frames;
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}

// The tracker alone on frames decoded once into memory, one thread, no graph: the serial step
// that bounds tracking's frames/s at 2 threads (the other thread decodes). Counters: ms_per_frame
// over every frame (global activations included) and local_ms_per_frame over the frames the
// local treatment kept.
void bm_tracker_only(benchmark::State& state, const std::string& path) {
  // Decoded once for all repetitions.
  static std::map<std::string, std::vector<video::Frame>> decoded;
  std::vector<video::Frame>& frames = decoded[path];
  if (frames.empty()) {
    video::VideoSource source(path, as_the_cli());
    while (auto f = source.next())
      frames.push_back(std::move(*f));
  }
  double total_ms = 0, local_ms = 0;
  long long runs = 0, local_frames = 0;
  for (auto _ : state) {
    tracking::Tracker tracker(tracking::TrackerParams{});
    for (const video::Frame& f : frames) {
      const tracking::TrackerOutput out =
          tracker.process({f.index, f.image, f.gray, nullptr, f.deferred_image});
      total_ms += out.ms;
      if (out.mode == eval::TrackRecord::Mode::Local && !out.lost) {
        local_ms += out.ms;
        ++local_frames;
      }
    }
    ++runs;
  }
  state.counters["ms_per_frame"] = total_ms / static_cast<double>(runs * frames.size());
  state.counters["local_ms_per_frame"] = local_frames > 0 ? local_ms / local_frames : 0.0;
}

void bm_dense(benchmark::State& state, const std::string& path, int threads) {
  long long pairs = 0;
  for (auto _ : state) {
    video::VideoSource source(path, as_the_cli());
    pipeline::GraphOptions options;
    options.threads = threads;
    const pipeline::RunReport report =
        pipeline::run_dense([&] { return source.next(); }, flow::LkParams::paper(), {}, options);
    pairs += report.frames - 1;
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(pairs), benchmark::Counter::kIsRate);
}

void register_video(const std::string& name, const std::string& path) {
  benchmark::RegisterBenchmark(("BM_Decode/" + name).c_str(), bm_decode<decode_all>, path)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  benchmark::RegisterBenchmark(("BM_DecodeGray/" + name).c_str(), bm_decode<decode_all_gray>, path)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  benchmark::RegisterBenchmark(("BM_DecodeOpenCV/" + name).c_str(), bm_decode<decode_all_opencv>,
                               path)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  for (int threads : kThreadCounts) {
    for (tracking::TrackMode mode : {tracking::TrackMode::Local, tracking::TrackMode::Global}) {
      const std::string bm = "BM_Track/" + name + "/" + tracking::to_string(mode) +
                             "/threads:" + std::to_string(threads);
      benchmark::RegisterBenchmark(bm.c_str(), bm_track, path, mode, threads)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(1);
    }
  }
  benchmark::RegisterBenchmark(("BM_GraphOnly/" + name + "/threads:2").c_str(), bm_graph_only, path)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1)
      ->Repetitions(5)
      ->ReportAggregatesOnly(true);
  benchmark::RegisterBenchmark(("BM_TrackerOnly/" + name).c_str(), bm_tracker_only, path)
      ->Unit(benchmark::kMillisecond)
      ->Repetitions(5)
      ->ComputeStatistics(
          "min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); })
      ->ReportAggregatesOnly(true);
  benchmark::RegisterBenchmark(("BM_TrackVsDecode/" + name + "/local/threads:2").c_str(),
                               bm_track_vs_decode, path, 2)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(1);
  for (int threads : kThreadCounts) {
    const std::string bm = "BM_Dense/" + name + "/threads:" + std::to_string(threads);
    benchmark::RegisterBenchmark(bm.c_str(), bm_dense, path, threads)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_video("synthetic640x480", synthetic_video());
  if (std::getenv("ROIFLOW_BENCH_HD") != nullptr) {
    const std::string hd = synthetic_hd_video();
    if (!hd.empty()) register_video("synthetic1920x1080_h264", hd);
  }
  if (const char* dir = std::getenv("ROIFLOW_VIDEOS")) {
    std::vector<fs::path> videos;
    for (const auto& entry : fs::directory_iterator(dir)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".avi" || ext == ".mp4" || ext == ".mkv") videos.push_back(entry.path());
    }
    std::sort(videos.begin(), videos.end());
    for (const fs::path& v : videos)
      register_video(v.stem().string(), v.string());
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
