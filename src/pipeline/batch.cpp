#include "pipeline/batch.hpp"

#include <oneapi/tbb/parallel_for_each.h>
#include <oneapi/tbb/task_arena.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "flow/color_code.hpp"
#include "flow/pyramid.hpp"
#include "pipeline/tbb_executor.hpp"
#include "video/track_log_sink.hpp"
#include "video/video_sink.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kVideoExtensions[] = {".avi", ".mp4",  ".mkv", ".mov", ".mpg", ".mpeg",
                                            ".m4v", ".webm", ".wmv", ".flv", ".ts",  ".mts"};

std::string lower(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool is_video_file(const fs::path& p) {
  const std::string ext = lower(p.extension().string());
  return std::find(std::begin(kVideoExtensions), std::end(kVideoExtensions), ext) !=
         std::end(kVideoExtensions);
}

std::string host_name() {
  char buffer[256] = {};
  if (gethostname(buffer, sizeof buffer - 1) != 0) return "host";
  std::string name = buffer;
  for (char& c : name) {
    if (c == '.' || c == '/') c = '_';
  }
  return name.empty() ? "host" : name;
}

// ".<stem>.partial.<host>.<pid>"
std::string partial_name(const std::string& stem) {
  return "." + stem + ".partial." + host_name() + "." + std::to_string(getpid());
}

// Removes partial folders of `stem` left by processes of this host that are gone.
void remove_stale_partials(const fs::path& out, const std::string& stem) {
  const std::string prefix = "." + stem + ".partial." + host_name() + ".";
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(out, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string pid_text = name.substr(prefix.size());
    if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos) continue;
    const long pid = std::stol(pid_text);
    if (pid == getpid()) continue;  // this process: another thread's (never: stems are unique)
    if (kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(e.path(), ec);
  }
}

nlohmann::ordered_json status_json(const BatchRow& row) {
  return {{"video", row.video},
          {"status", row.status},
          {"frames", row.frames},
          {"fps", row.fps},
          {"seconds", row.seconds}};
}

// The row of a finished folder (its status.json), or nothing when the folder is not a finished one.
std::optional<BatchRow> finished_row(const std::string& video, const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return std::nullopt;
  std::ifstream in(folder / "status.json");
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    BatchRow row;
    row.video = video;
    row.status = j.at("status").get<std::string>();
    row.frames = j.at("frames").get<long long>();
    row.fps = j.at("fps").get<double>();
    row.seconds = j.at("seconds").get<double>();
    row.skipped = true;
    row.folder = folder.string();
    if (row.status != "done") return std::nullopt;
    return row;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

bool cancelled(const BatchOptions& options) {
  return options.cancel != nullptr && options.cancel->load();
}

// Runs one video into `dir`; returns the frames done. Throws roiflow::Error on failure.
long long run_track(const std::string& video, const fs::path& dir, const BatchOptions& options,
                    const TbbExecutor& executor, bool& stopped) {
  video::VideoSourceParams sp;
  sp.max_frames = options.max_frames;
  sp.defer_colour = true;
  video::VideoSource source(video, sp);
  tracking::Tracker tracker(options.tracker, &executor);
  video::TrackLogWriter log((dir / "track.csv").string());
  long long frames = 0;
  try {
    while (!cancelled(options)) {
      std::optional<video::Frame> f = source.next();
      if (!f) break;
      const tracking::TrackerOutput out =
          tracker.process({f->index, f->image, f->gray, nullptr, f->deferred_image});
      log.write(out.record());
      ++frames;
    }
  } catch (...) {
    tracker.finish_background_work();
    throw;
  }
  tracker.finish_background_work();
  log.close();
  stopped = cancelled(options);
  if (source.status().state == video::SourceStatus::State::kStopped) {
    throw Error("input " + source.status().message);
  }
  return frames;
}

long long run_dense_job(const std::string& video, const fs::path& dir, const BatchOptions& options,
                        const TbbExecutor& executor, bool& stopped) {
  video::VideoSourceParams sp;
  sp.max_frames = options.max_frames;
  video::VideoSource source(video, sp);
  video::VideoSink sink((dir / "flow.avi").string(), source.fps(), source.size());
  flow::DenseLK lk(options.lk, &executor);
  flow::FlowResult result;
  flow::Pyramid previous, current;
  const int levels = flow::flow_pyramid_levels(source.size(), options.lk, {});
  bool have_previous = false;
  long long frames = 0;
  while (!cancelled(options)) {
    std::optional<video::Frame> f = source.next();
    if (!f) break;
    flow::build_pyramid(f->gray, levels, options.lk.sigma, current);
    if (have_previous) {
      lk.calc(previous, current, result);
      sink.write(flow::flow_to_color(result.flow, options.max_motion));
    }
    std::swap(previous, current);
    have_previous = true;
    ++frames;
  }
  sink.close();
  stopped = cancelled(options);
  if (source.status().state == video::SourceStatus::State::kStopped) {
    throw Error("input " + source.status().message);
  }
  return frames;
}

BatchRow run_one(const std::string& video, const fs::path& out, const std::string& stem,
                 const BatchOptions& options, const TbbExecutor& executor) {
  BatchRow row;
  row.video = video;
  const fs::path final_dir = out / stem;
  if (std::optional<BatchRow> done = finished_row(video, final_dir)) return *done;
  remove_stale_partials(out, stem);
  const fs::path partial = out / partial_name(stem);
  std::error_code ec;
  fs::remove_all(partial, ec);
  const auto start = Clock::now();
  try {
    if (!fs::create_directories(partial, ec) && ec) {
      throw Error("batch: cannot create '" + partial.string() + "': " + ec.message());
    }
    bool stopped = false;
    row.frames = options.job == BatchJob::Track
                     ? run_track(video, partial, options, executor, stopped)
                     : run_dense_job(video, partial, options, executor, stopped);
    row.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    row.fps = row.seconds > 0 ? static_cast<double>(row.frames) / row.seconds : 0.0;
    if (stopped) {
      row.status = "cancelled";
      fs::remove_all(partial, ec);
      return row;
    }
    row.status = "done";
    write_text_atomically((partial / "status.json").string(), status_json(row).dump(2) + "\n");
    fs::rename(partial, final_dir, ec);
    if (ec) {
      // Another run finished this video first: its folder stands, ours goes.
      if (std::optional<BatchRow> done = finished_row(video, final_dir)) {
        fs::remove_all(partial, ec);
        return *done;
      }
      throw Error("batch: cannot rename '" + partial.string() + "' to '" + final_dir.string() +
                  "': " + ec.message());
    }
    row.folder = final_dir.string();
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
    row.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    fs::remove_all(partial, ec);
  }
  return row;
}

}  // namespace

std::vector<std::string> batch_inputs(const std::string& input) {
  std::error_code ec;
  const fs::path path(input);
  std::vector<std::string> videos;
  if (fs::is_directory(path, ec)) {
    for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
      if (e.is_regular_file() && is_video_file(e.path())) videos.push_back(e.path().string());
    }
    std::sort(videos.begin(), videos.end());
    if (videos.empty()) throw Error("batch: no video files in '" + input + "'");
    return videos;
  }
  if (!fs::exists(path, ec)) throw Error("batch: '" + input + "' does not exist");
  const std::string ext = lower(path.extension().string());
  if (ext != ".txt" && ext != ".lst") return {input};
  std::ifstream in(path);
  if (!in) throw Error("batch: cannot read '" + input + "'");
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const fs::path entry(line.substr(first));
    videos.push_back(entry.is_absolute() ? entry.string() : (path.parent_path() / entry).string());
  }
  if (videos.empty()) throw Error("batch: the list '" + input + "' names no video");
  return videos;
}

std::vector<std::string> batch_names(const std::vector<std::string>& videos) {
  std::vector<std::string> names;
  std::map<std::string, std::string> seen;
  for (const std::string& v : videos) {
    std::string stem = fs::path(v).stem().string();
    if (stem.empty() || stem[0] == '.') stem = "video" + stem;
    const auto [it, inserted] = seen.emplace(stem, v);
    if (!inserted) {
      throw Error("batch: '" + it->second + "' and '" + v + "' would share the output folder '" +
                  stem + "'; rename one");
    }
    names.push_back(stem);
  }
  return names;
}

std::vector<BatchRow> run_batch(const std::vector<std::string>& videos,
                                const BatchOptions& options) {
  if (options.out_dir.empty()) throw Error("batch: no output folder");
  if (options.threads < 0 || options.threads > kMaxThreads) {
    throw Error("batch: threads must be in 0.." + std::to_string(kMaxThreads) + ", got " +
                std::to_string(options.threads));
  }
  if (options.parallel < 0) {
    throw Error("batch: parallel must be >= 0, got " + std::to_string(options.parallel));
  }
  if (options.job == BatchJob::Track) {
    if (options.tracker.init) throw Error("batch: track takes no init box (one per video)");
    options.tracker.validate();
  } else {
    options.lk.validate();
  }
  const std::vector<std::string> names = batch_names(videos);
  const fs::path out(options.out_dir);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (!fs::is_directory(out, ec)) throw Error("batch: cannot create '" + options.out_dir + "'");

  const int threads =
      options.threads == 0 ? oneapi::tbb::info::default_concurrency() : options.threads;
  // Tracking: one thread of the arena stays out of the videos' loops, for the trackers'
  // background work (an enqueued task, which a thread waiting inside a video does not take).
  const int cap = options.job == BatchJob::Track && threads > 1 ? threads - 1 : threads;
  const int parallel = std::clamp(options.parallel == 0 ? cap : options.parallel, 1, cap);
  std::vector<BatchRow> rows(videos.size());
  std::mutex report;
  std::vector<BatchRow> ended(videos.size());  // under `report`: what batch.csv holds
  std::vector<std::size_t> order(videos.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  const TbbExecutor executor;
  tbb::task_arena arena(threads);
  // At most `parallel` videos at once: that many workers, each taking the next video.
  std::atomic<std::size_t> next{0};
  std::vector<int> workers(
      static_cast<std::size_t>(std::min<std::size_t>(parallel, videos.size())));
  arena.execute([&] {
    tbb::parallel_for_each(workers.begin(), workers.end(), [&](int) {
      for (std::size_t i = next++; i < videos.size(); i = next++) {
        rows[i] = run_one(videos[i], out, names[i], options, executor);
        std::lock_guard<std::mutex> lock(report);
        ended[i] = rows[i];
        if (!options.csv.empty()) write_batch_csv(options.csv, ended);
        if (options.on_row) options.on_row(rows[i]);
      }
    });
  });
  if (!options.csv.empty()) write_batch_csv(options.csv, rows);
  return rows;
}

void write_batch_csv(const std::string& path, const std::vector<BatchRow>& rows) {
  std::string text = "video,status,frames,fps,seconds\n";
  for (const BatchRow& r : rows) {
    if (r.video.empty()) continue;
    text += csv_field(r.video) + "," + csv_field(r.status) + "," + std::to_string(r.frames) + "," +
            fixed(r.fps, 2) + "," + fixed(r.seconds, 3) + "\n";
  }
  write_text_atomically(path, text);
}

std::string batch_row_line(const BatchRow& row) {
  if (row.skipped) return "skipped " + row.video + " (done earlier)";
  if (row.status == "done") {
    return "done    " + row.video + " (" + std::to_string(row.frames) + " frames, " +
           fixed(row.fps, 1) + " fps) -> " + row.folder;
  }
  const std::size_t colon = row.status.find(':');
  if (colon == std::string::npos) return row.status + "  " + row.video;
  return row.status.substr(0, colon) + "  " + row.video + ":" + row.status.substr(colon + 1);
}

BatchTally tally(const std::vector<BatchRow>& rows) {
  BatchTally t;
  for (const BatchRow& r : rows) {
    ++(r.skipped                 ? t.skipped
       : r.status == "done"      ? t.ran
       : r.status == "cancelled" ? t.cancelled
                                 : t.failed);
  }
  return t;
}

std::string batch_summary_line(const std::vector<BatchRow>& rows, const std::string& csv) {
  const BatchTally t = tally(rows);
  return "batch: " + std::to_string(rows.size()) + " videos: " + std::to_string(t.ran) + " run, " +
         std::to_string(t.skipped) + " already done, " + std::to_string(t.failed) + " failed" +
         (t.cancelled > 0 ? ", " + std::to_string(t.cancelled) + " cancelled" : std::string()) +
         (csv.empty() ? std::string() : "; wrote " + csv);
}

Ending batch_ending(const std::vector<BatchRow>& rows) {
  if (caught_signal() != 0) {
    return {128 + caught_signal(), "interrupted; finished videos are kept, run again to resume"};
  }
  const long long failed = tally(rows).failed;
  if (failed == 0) return {};
  return {1, std::to_string(failed) + " of " + std::to_string(rows.size()) +
                 " videos failed (see batch.csv); run again to retry them"};
}

}  // namespace roiflow::pipeline
