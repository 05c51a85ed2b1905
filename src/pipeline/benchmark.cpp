#include "pipeline/benchmark.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <set>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/otb_plot.hpp"
#include "tracking/box_tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {
namespace fs = std::filesystem;

namespace {

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// OpenCV at one thread while it lives (its thread count is process-wide).
class OpenCvSerial {
 public:
  OpenCvSerial() : previous_(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~OpenCvSerial() { cv::setNumThreads(previous_); }
  OpenCvSerial(const OpenCvSerial&) = delete;
  OpenCvSerial& operator=(const OpenCvSerial&) = delete;

 private:
  int previous_;
};

std::string box_text(const cv::Rect2f& b) {
  return std::to_string(b.x) + "," + std::to_string(b.y) + "," + std::to_string(b.width) + "," +
         std::to_string(b.height);
}

void check_trackers(const std::vector<std::string>& trackers) {
  if (trackers.empty()) throw Error("no tracker to benchmark");
  std::set<std::string> seen;
  for (const std::string& t : trackers) {
    tracking::make_box_tracker(t);  // throws for an unknown name, listing the known ones
    if (!seen.insert(t).second) throw Error("tracker '" + t + "' is listed twice");
  }
}

struct Job {
  eval::OtbSequence sequence;
  std::optional<video::VideoSource> source;
  std::vector<eval::TrackerRun> runs;
};

// Opens the sequence's frames and checks them against its ground truth.
void open_job(Job& job, long long max_frames, cv::Point2f shift) {
  const eval::OtbSequence& s = job.sequence;
  video::VideoSourceParams params;
  params.max_frames = max_frames;
  job.source.emplace(s.dir, params);
  const long long images = job.source->frame_count_hint();
  const long long boxes = static_cast<long long>(s.truth.size());
  if (max_frames == 0 ? images != boxes : images > boxes) {
    throw Error(s.name + ": groundtruth_rect.txt holds " + std::to_string(boxes) +
                " boxes but the sequence has " + std::to_string(images) +
                " frames (one box per frame)");
  }
  const cv::Size size = job.source->size();
  const cv::Rect2f first = s.truth.front();
  const cv::Rect2f frame(0.f, 0.f, static_cast<float>(size.width), static_cast<float>(size.height));
  const cv::Rect2f inside = first & frame;
  if (!(inside.width >= 2 && inside.height >= 2)) {
    throw Error(s.name + ": the first ground-truth box " + box_text(first) + " lies outside the " +
                std::to_string(size.width) + "x" + std::to_string(size.height) + " frame");
  }
  const cv::Rect2f start = (first + shift) & frame;
  if (!(start.width >= 2 && start.height >= 2)) {
    throw Error(s.name + ": the first ground-truth box " + box_text(first) +
                " shifted by --init-shift leaves the " + std::to_string(size.width) + "x" +
                std::to_string(size.height) + " frame");
  }
}

void run_job(Job& job, const BenchmarkOptions& options) {
  std::vector<std::unique_ptr<tracking::BoxTracker>> trackers;
  bool any_opencv = false;
  for (const std::string& name : options.trackers) {
    trackers.push_back(tracking::make_box_tracker(name, options.roiflow));
    any_opencv = any_opencv || name != "roiflow";
  }
  job.runs.assign(trackers.size(), {});
  long long frames = 0;
  while (std::optional<video::Frame> frame = job.source->next()) {
    const cv::Mat bgr = any_opencv ? tracking::bgr_picture(*frame) : cv::Mat();
    for (std::size_t t = 0; t < trackers.size(); ++t) {
      const double start = thread_cpu_s();
      const tracking::BoxUpdate u =
          frames == 0
              ? trackers[t]->start(*frame, bgr, job.sequence.truth.front() + options.init_shift)
              : trackers[t]->next(*frame, bgr);
      const double spent = thread_cpu_s() - start;
      job.runs[t].cpu_s += spent;
      job.runs[t].ms.push_back(1000.0 * spent);
      job.runs[t].boxes.push_back(u.box);
      job.runs[t].lost.push_back(u.lost);
    }
    ++frames;
  }
  const video::SourceStatus& status = job.source->status();
  if (status.state == video::SourceStatus::State::kStopped) {
    throw Error(job.sequence.name + ": " + status.message);
  }
  job.source.reset();  // its buffers go now, not with the whole run
}

}  // namespace

BenchmarkResult run_benchmark(const BenchmarkOptions& options) {
  if (options.threads < 1 || options.threads > kMaxThreads) {
    throw Error("benchmark threads " + std::to_string(options.threads) + " is not in 1.." +
                std::to_string(kMaxThreads));
  }
  if (options.max_frames < 0) throw Error("benchmark max_frames must be >= 0");
  if (!(std::abs(options.init_shift.x) <= 1000 && std::abs(options.init_shift.y) <= 1000)) {
    throw Error("benchmark init shift must be finite and at most 1000 pixels each way");
  }
  check_trackers(options.trackers);
  options.roiflow.validate();

  BenchmarkResult result;
  std::vector<eval::OtbSequence> found = eval::find_otb_sequences(options.dir, &result.skipped);
  std::vector<Job> jobs;
  for (const std::string& name : options.sequences) {
    if (std::none_of(found.begin(), found.end(),
                     [&](const eval::OtbSequence& s) { return s.name == name; })) {
      throw Error("no sequence '" + name + "' in '" + options.dir + "'");
    }
  }
  for (eval::OtbSequence& s : found) {
    if (!options.sequences.empty() && std::find(options.sequences.begin(), options.sequences.end(),
                                                s.name) == options.sequences.end()) {
      continue;
    }
    jobs.push_back({std::move(s), std::nullopt, {}});
  }
  for (Job& job : jobs)
    open_job(job, options.max_frames, options.init_shift);

  std::mutex report_mutex;
  {
    const OpenCvSerial serial;
    tbb::task_arena arena(options.threads);
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, jobs.size(), 1),
          [&](const tbb::blocked_range<std::size_t>& range) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
              run_job(jobs[i], options);
              if (options.on_sequence) {
                const std::lock_guard<std::mutex> lock(report_mutex);
                options.on_sequence(jobs[i].sequence.name + ": " +
                                    std::to_string(jobs[i].runs.front().boxes.size()) +
                                    " frames, " + std::to_string(options.trackers.size()) +
                                    " trackers");
              }
            }
          },
          tbb::simple_partitioner());
    });
  }

  for (const Job& job : jobs) {
    for (std::size_t t = 0; t < options.trackers.size(); ++t) {
      result.rows.push_back(
          eval::score_run(job.sequence.name, options.trackers[t], job.sequence.truth, job.runs[t]));
      result.runs.push_back(job.runs[t]);
    }
  }
  result.means = eval::tracker_means(result.rows, options.trackers);
  return result;
}

void check_benchmark_out(const std::string& out_dir) {
  if (out_dir.empty()) throw Error("--out: no folder given");
  std::error_code ec;
  fs::path p(out_dir);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw Error("--out: '" + out_dir + "' is not a directory");
    if (access(p.c_str(), W_OK) != 0) throw Error("--out: '" + out_dir + "' is not writable");
    return;
  }
  // The nearest existing ancestor must be a writable directory.
  fs::path up = fs::absolute(p, ec).parent_path();
  while (!up.empty() && !fs::exists(up, ec) && up != up.root_path())
    up = up.parent_path();
  if (!fs::is_directory(up, ec) || access(up.c_str(), W_OK) != 0) {
    throw Error("--out: cannot make folder '" + out_dir + "' ('" + up.string() +
                "' is not a writable directory)");
  }
}

std::vector<std::string> write_benchmark(const BenchmarkResult& result, const std::string& out_dir,
                                         bool tracks) {
  check_benchmark_out(out_dir);
  // Everything is rendered before the first file is written.
  const std::string md = eval::format_benchmark_markdown(result.rows, result.means);
  const std::string csv = eval::format_benchmark_csv(result.rows, result.means);
  const std::string success = report::plot_svg(report::success_plot(result.means));
  const std::string precision = report::plot_svg(report::precision_plot(result.means));
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw Error("--out: cannot make folder '" + out_dir + "': " + ec.message());
  const fs::path dir(out_dir);
  std::vector<std::string> written;
  for (const auto& [name, text] : {std::pair<const char*, const std::string&>{"benchmark.md", md},
                                   {"benchmark.csv", csv},
                                   {"success.svg", success},
                                   {"precision.svg", precision}}) {
    const std::string path = (dir / name).string();
    write_text_atomically(path, text);
    written.push_back(path);
  }
  if (tracks) {
    if (result.runs.size() != result.rows.size()) {
      throw Error("benchmark: " + std::to_string(result.runs.size()) + " runs for " +
                  std::to_string(result.rows.size()) + " rows");
    }
    for (std::size_t i = 0; i < result.rows.size(); ++i) {
      const fs::path folder = dir / "tracks" / result.rows[i].sequence;
      fs::create_directories(folder, ec);
      if (ec) throw Error("--out: cannot make folder '" + folder.string() + "': " + ec.message());
      write_text_atomically((folder / (result.rows[i].tracker + ".csv")).string(),
                            eval::track_log_csv(result.runs[i]));
    }
    written.push_back((dir / "tracks").string());
  }
  return written;
}

std::string benchmark_text(const BenchmarkResult& result, int threads,
                           const std::vector<std::string>& written) {
  const std::size_t trackers = result.means.size();
  return eval::format_benchmark_markdown(result.rows, result.means) + "\nbenchmarked " +
         std::to_string(trackers) + " trackers on " +
         std::to_string(result.rows.size() / std::max<std::size_t>(1, trackers)) + " sequences, " +
         std::to_string(threads) + " at once; wrote " + joined(written) + "\n";
}

}  // namespace roiflow::pipeline
