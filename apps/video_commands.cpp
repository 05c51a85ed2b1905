// roiflow track, dense and demo: the video subcommands, each a run of the tbb::flow graph.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "eval/otb_score.hpp"
#include "eval/track_log.hpp"
#include "eval/tracking_scene.hpp"
#include "flow/color_code.hpp"
#include "pipeline/frame_graph.hpp"
#include "pipeline/mot_run.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/annotate.hpp"
#include "report/plot.hpp"
#include "report/progress.hpp"
#include "report/run_stats.hpp"
#include "stages/track_log_sink.hpp"
#include "stages/tracker.hpp"
#include "stages/video_sink.hpp"
#include "stages/video_source.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Signals: SIGINT / SIGTERM stop the source; the frames in flight finish, outputs are closed,
// the summary is printed, and the exit code is 128 + the signal.

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};

extern "C" void on_signal(int signal) {
  g_signal.store(signal);
  g_cancel.store(true);
}

class SignalScope {
 public:
  SignalScope() {
    previous_int_ = std::signal(SIGINT, on_signal);
    previous_term_ = std::signal(SIGTERM, on_signal);
  }
  ~SignalScope() {
    std::signal(SIGINT, previous_int_);
    std::signal(SIGTERM, previous_term_);
  }
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

 private:
  void (*previous_int_)(int) = SIG_DFL;
  void (*previous_term_)(int) = SIG_DFL;
};

int default_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

// "x,y,w,h" (commas and/or spaces) with a positive size.
cv::Rect2f parse_box(const std::string& text, const std::string& option) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ',') c = ' ';
  }
  std::istringstream in(spaced);
  double v[4];
  for (double& x : v) {
    if (!(in >> x) || !std::isfinite(x)) {
      throw UsageError(option + ": expected x,y,w,h, got '" + text + "'");
    }
  }
  std::string rest;
  if (in >> rest) throw UsageError(option + ": expected 4 numbers x,y,w,h, got '" + text + "'");
  if (!(v[2] > 0 && v[3] > 0)) {
    throw UsageError(option + ": the box needs a positive width and height, got '" + text + "'");
  }
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
          static_cast<float>(v[3])};
}

// The tracker's own criterion, checked before the run: at least 2x2 pixels of the --init box
// (given as `text`) inside the first frame.
void check_init_inside(const stages::TrackerParams& params, const std::string& text,
                       cv::Size size) {
  if (!params.init) return;
  const cv::Rect2f inside = *params.init & cv::Rect2f(0.f, 0.f, static_cast<float>(size.width),
                                                      static_cast<float>(size.height));
  if (inside.width < 2.f || inside.height < 2.f) {
    throw UsageError("--init: the box " + text + " lies outside the " + size_string(size) +
                     " frame (less than 2x2 pixels of it inside)");
  }
}

void check_log_path(const std::string& path) {
  check_output_path(path, "--log");
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".csv" && ext != ".json") {
    throw UsageError("--log: '" + path + "' must end in .csv or .json");
  }
}

void check_summary_path(const std::string& path) {
  check_output_path(path, "--summary");
}

// The output options every video subcommand shares.
struct RunOutputs {
  std::string video;    // --out
  std::string summary;  // --summary
  bool progress = true;
};

// The per-stage figures that the summaries report.
double stage_ms(const nlohmann::ordered_json& stats, const char* stage) {
  const auto& stages = stats.at("stages");
  return stages.contains(stage) ? stages.at(stage).at("ms_total").get<double>() : 0.0;
}

std::string plural(long long n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

// Ends a run that a signal or a broken input cut short: what was written stays, the exit code
// says why.
struct Ending {
  int exit_code = 0;
  std::string message;
};

Ending ending(const pipeline::RunReport& report, const stages::SourceStatus* status) {
  if (report.cancelled && g_signal.load() != 0) {
    const int sig = g_signal.load();
    return {128 + sig, std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                           " after " + plural(report.frames, "frame") +
                           "; outputs hold every frame processed"};
  }
  if (status != nullptr && status->state == stages::SourceStatus::State::kStopped) {
    return {1, "input " + status->message + "; outputs hold the " + plural(report.frames, "frame") +
                   " before it"};
  }
  return {};
}

// ---------------------------------------------------------------------------------------------
// roiflow track

report::TrackAnnotation annotation(const stages::TrackerOutput& out) {
  report::TrackAnnotation a;
  a.index = out.index;
  a.has_target = out.has_target;
  a.box = out.box;
  a.velocity = out.velocity;
  a.global = out.mode == eval::TrackRecord::Mode::Global;
  a.lost = out.lost;
  a.region = out.region;
  a.region_flow = out.region_flow;
  return a;
}

// What to read of the input and how far ahead (track and dense).
struct SourceOptions {
  long long start = 0;
  long long max_frames = 0;
  int in_flight = 0;
  int decode_threads = 0;

  stages::VideoSourceParams params() const {
    stages::VideoSourceParams p;
    p.start = start;
    p.max_frames = max_frames;
    p.decode_threads = decode_threads;
    // Colour is converted only for the frames that need it: the video sink's and the few the
    // tracker learns appearance or background from (Frame::picture()).
    p.defer_colour = true;
    return p;
  }
};

struct TrackCommand {
  LkOptions lk;
  std::string input;
  std::string init;                // the single --init (single-object tracker)
  std::vector<std::string> inits;  // every --init
  std::string init_file;           // --init-file: id,x,y,w,h lines
  std::string mot;                 // --mot: MOTChallenge output
  bool single = false;             // --single: one object even without --init
  int roi = 50;
  double lk_patches = stages::LocalTrackerParams{}.lk_patches;
  std::string mode = "local";
  std::string log;
  RunOutputs out;
  SourceOptions source;
  bool compare = false;  // --compare: local and global mode side by side
  std::string compare_out = "out/compare";
  std::vector<int> compare_patches;
};

struct TrackRun {
  pipeline::RunReport report;
  nlohmann::ordered_json summary;
  std::vector<eval::TrackRecord> records;  // kept when asked (the demo scores them)
};

// Runs the tracker over `source` with the sinks the options ask for.
TrackRun track(const pipeline::FrameSource& source, cv::Size size, double fps, long long frame_hint,
               const stages::TrackerParams& params, int threads, int in_flight,
               const std::string& log_path, const RunOutputs& out, bool keep_records) {
  pipeline::TbbExecutor tiles;
  stages::Tracker tracker(params, &tiles);
  std::optional<stages::TrackLogWriter> log;
  if (!log_path.empty()) log.emplace(log_path);
  std::optional<stages::VideoSink> video;
  if (!out.video.empty()) video.emplace(out.video, fps, size);
  report::Progress progress(std::cerr, frame_hint,
                            out.progress && report::Progress::stderr_is_terminal());

  TrackRun run;
  long long lost = 0;
  std::vector<pipeline::TrackSink> sinks;
  sinks.push_back({"log", [&](const pipeline::TrackedFrame& f) {
                     const eval::TrackRecord r = f.output->record();
                     if (r.lost) ++lost;
                     if (log) log->write(r);
                     if (keep_records) run.records.push_back(r);
                   }});
  if (video) {
    sinks.push_back({"video", [&](const pipeline::TrackedFrame& f) {
                       video->write(
                           report::annotate_frame(f.frame->picture(), annotation(*f.output)));
                     }});
  }
  sinks.push_back(
      {"progress", [&](const pipeline::TrackedFrame& f) { progress.update(f.seq + 1); }});

  report::RunStats stats;
  pipeline::GraphOptions options;
  options.threads = threads;
  options.max_in_flight = in_flight;
  options.cancel = &g_cancel;
  options.stats = &stats;
  run.report = pipeline::run_tracking(source, tracker, sinks, options);
  progress.finish();
  if (log) log->close();
  if (video) video->close();

  const nlohmann::ordered_json s = stats.to_json(run.report.wall_s);
  const double tracker_ms = stage_ms(s, "pyramid") + stage_ms(s, "track");
  run.summary = {
      {"mode", stages::to_string(params.mode)},
      {"frames", run.report.frames},
      {"global_activations", tracker.global_activations()},
      {"lost_frames", lost},
      {"fps", run.report.wall_s > 0 ? run.report.frames / run.report.wall_s : 0.0},
      {"tracker_fps", tracker_ms > 0 ? run.report.frames / (tracker_ms / 1000.0) : 0.0},
      {"tracker_ms_per_frame",
       run.report.frames > 0 ? tracker_ms / static_cast<double>(run.report.frames) : 0.0},
      {"wall_s", run.report.wall_s},
      {"threads", threads},
      {"roi", params.roi},
      {"max_in_flight", run.report.max_in_flight},
      {"peak_rss_mb", report::peak_rss_mb()},
      {"stages", s.at("stages")}};
  return run;
}

stages::TrackerParams tracker_params(const TrackCommand& cmd) {
  stages::TrackerParams params;
  params.lk = lk_params(cmd.lk);
  params.mode = stages::track_mode_from_string(cmd.mode);
  params.roi = cmd.roi;
  params.local.lk_patches = cmd.lk_patches;
  if (!cmd.init.empty()) params.init = parse_box(cmd.init, "--init");
  try {
    params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  return params;
}

void print_track_summary(const std::string& what, const nlohmann::ordered_json& s,
                         const std::vector<std::string>& written) {
  std::cout << what << ": " << s.at("frames").get<long long>() << " frames in "
            << fixed(s.at("wall_s").get<double>(), 2) << " s, "
            << fixed(s.at("fps").get<double>(), 1) << " fps overall, tracker "
            << fixed(s.at("tracker_fps").get<double>(), 1) << " fps ("
            << fixed(s.at("tracker_ms_per_frame").get<double>(), 3)
            << " ms/frame, decode excluded), mode " << s.at("mode").get<std::string>() << "\n"
            << "  global activations " << s.at("global_activations").get<long long>()
            << ", frames lost " << s.at("lost_frames").get<long long>() << ", "
            << s.at("threads").get<int>() << " threads\n";
  if (!written.empty()) {
    std::string list;
    for (const std::string& w : written)
      list += (list.empty() ? "" : ", ") + w;
    std::cout << "  wrote " << list << "\n";
  }
}

// ---------------------------------------------------------------------------------------------
// roiflow track --compare: the same input in local and in global mode (paper Sec. 4.4-4.5,
// Fig. 12). Each mode runs in a child process of this binary, one after the other, so that
// each has the machine to itself and its peak memory is its own.

// Thrown when a signal stopped a child run: the comparison is abandoned.
struct CompareInterrupted {
  int signal = 0;
};

// One child run, summarised from its --summary and the ms column of its --log.
struct CompareRun {
  std::string mode;
  int patch = 0;
  nlohmann::json summary;
  std::vector<double> ms;  // tracker time of every frame
  double ms_median = 0, ms_p95 = 0, ms_mean = 0;
};

// Linear interpolation between order statistics; `sorted` is not empty.
double percentile(const std::vector<double>& sorted, double p) {
  const double at = p * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(at);
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (at - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

std::string exact(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// The command line of one child: everything the user gave that changes the run, the mode, the
// patch, and the child's log and summary.
std::vector<std::string> child_args(const TrackCommand& cmd, const std::string& mode, int patch,
                                    const std::string& log, const std::string& summary) {
  std::vector<std::string> a = {"roiflow",
                                "track",
                                cmd.input,
                                "--mode",
                                mode,
                                "--roi",
                                std::to_string(cmd.roi),
                                "--lk-patches",
                                exact(cmd.lk_patches),
                                "--log",
                                log,
                                "--summary",
                                summary,
                                "--no-progress",
                                "--start",
                                std::to_string(cmd.source.start),
                                "--max-frames",
                                std::to_string(cmd.source.max_frames),
                                "--in-flight",
                                std::to_string(cmd.source.in_flight),
                                "--decode-threads",
                                std::to_string(cmd.source.decode_threads),
                                "--preset",
                                cmd.lk.preset,
                                "--patch",
                                std::to_string(patch),
                                "--threads",
                                std::to_string(cmd.lk.threads)};
  if (!cmd.init.empty()) a.insert(a.end(), {"--init", cmd.init});
  a.push_back("--single");
  const LkOptions& lk = cmd.lk;
  if (lk.levels) a.insert(a.end(), {"--levels", *lk.levels});
  if (lk.expected_motion) a.insert(a.end(), {"--expected-motion", exact(*lk.expected_motion)});
  if (lk.search_radius) a.insert(a.end(), {"--search-radius", std::to_string(*lk.search_radius)});
  if (lk.coarsest_side) {
    a.insert(a.end(), {"--coarsest-side", std::to_string(*lk.coarsest_side)});
  }
  if (lk.fuse_far_step) a.insert(a.end(), {"--fuse-far-step", std::to_string(*lk.fuse_far_step)});
  if (lk.fuse_far_finest_level) {
    a.insert(a.end(), {"--fuse-far-finest-level", std::to_string(*lk.fuse_far_finest_level)});
  }
  if (lk.fuse_step) a.insert(a.end(), {"--fuse-step", std::to_string(*lk.fuse_step)});
  if (lk.fuse_finest_level) {
    a.insert(a.end(), {"--fuse-finest-level", std::to_string(*lk.fuse_finest_level)});
  }
  if (lk.mask_outside) a.insert(a.end(), {"--mask-outside", std::to_string(*lk.mask_outside)});
  if (lk.finest_level) a.insert(a.end(), {"--finest-level", std::to_string(*lk.finest_level)});
  if (lk.iterations) a.insert(a.end(), {"--iterations", std::to_string(*lk.iterations)});
  if (lk.level_median) a.insert(a.end(), {"--level-median", std::to_string(*lk.level_median)});
  if (lk.final_median) a.insert(a.end(), {"--final-median", std::to_string(*lk.final_median)});
  if (lk.sigma) a.insert(a.end(), {"--sigma", exact(*lk.sigma)});
  if (lk.lambda) a.insert(a.end(), {"--lambda", exact(*lk.lambda)});
  if (lk.robust_scale) a.insert(a.end(), {"--robust-scale", exact(*lk.robust_scale)});
  if (lk.derivative) a.insert(a.end(), {"--derivative", *lk.derivative});
  return a;
}

// Runs this binary with `args` (stdout discarded, stderr to `err_path`) and waits for it. A
// signal that reaches this process is passed on to the child, which then ends its run the way
// track does. Returns the exit code, 128 + the signal when the child was killed.
int run_child(const std::vector<std::string>& args, const std::string& err_path) {
  // The running binary itself, even when a rebuild has since replaced the file on disk.
  const fs::path exe = "/proc/self/exe";
  std::vector<char*> argv;
  for (const std::string& arg : args)
    argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);

  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDERR_FILENO, err_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (rc != 0) {
    throw Error("--compare: cannot start '" + exe.string() + "': " + std::strerror(rc));
  }
  bool forwarded = false;
  int status = 0;
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      throw Error(std::string("--compare: waiting for the child run failed: ") +
                  std::strerror(errno));
    }
    if (!forwarded && g_signal.load() != 0) {
      kill(pid, g_signal.load());
      forwarded = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 1;
}

// The child's own error line, without its "roiflow: error: " prefix.
std::string child_error(const std::string& err_path) {
  std::ifstream in(err_path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  const std::string prefix = "roiflow: error: ";
  if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  return last;
}

CompareRun compare_run(const TrackCommand& cmd, const std::string& mode, int patch,
                       const fs::path& log_dir, const fs::path& temp_dir, const std::string& stem) {
  const std::string log = (log_dir / (stem + ".csv")).string();
  const std::string summary = (log_dir / (stem + ".json")).string();
  const std::string err = (temp_dir / (stem + ".err")).string();
  if (report::Progress::stderr_is_terminal() && cmd.out.progress) {
    std::cerr << "compare: " << mode << " mode, patch " << patch << " ..." << std::endl;
  }
  const int code = run_child(child_args(cmd, mode, patch, log, summary), err);
  if (code != 0) {
    if (g_signal.load() != 0) throw CompareInterrupted{g_signal.load()};
    const std::string why = child_error(err);
    throw Error("--compare: the " + mode + " run (patch " + std::to_string(patch) +
                ") failed with exit code " + std::to_string(code) +
                (why.empty() ? std::string() : ": " + why));
  }
  CompareRun run;
  run.mode = mode;
  run.patch = patch;
  std::ifstream in(summary);
  try {
    run.summary = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error("--compare: cannot read the " + mode + " run's summary '" + summary +
                "': " + e.what());
  }
  for (const eval::TrackRecord& r : eval::read_track_csv(log))
    run.ms.push_back(r.ms);
  if (run.ms.empty()) throw Error("--compare: the " + mode + " run tracked no frame");
  std::vector<double> sorted = run.ms;
  std::sort(sorted.begin(), sorted.end());
  run.ms_median = percentile(sorted, 0.5);
  run.ms_p95 = percentile(sorted, 0.95);
  for (double v : sorted)
    run.ms_mean += v;
  run.ms_mean /= static_cast<double>(sorted.size());
  return run;
}

double summary_number(const CompareRun& run, const char* key) {
  const auto it = run.summary.find(key);
  if (it == run.summary.end() || !it->is_number()) {
    throw Error("--compare: the " + run.mode + " run's summary has no number '" + key + "'");
  }
  return it->get<double>();
}

nlohmann::ordered_json compare_json(const CompareRun& r) {
  return {{"mode", r.mode},
          {"patch", r.patch},
          {"frames", summary_number(r, "frames")},
          {"fps", summary_number(r, "fps")},
          {"tracker_fps", summary_number(r, "tracker_fps")},
          {"ms_median", r.ms_median},
          {"ms_p95", r.ms_p95},
          {"ms_mean", r.ms_mean},
          {"global_activations", summary_number(r, "global_activations")},
          {"peak_rss_mb", summary_number(r, "peak_rss_mb")}};
}

std::string compare_csv_row(const CompareRun& r) {
  return std::to_string(r.patch) + "," + r.mode + "," +
         std::to_string(std::llround(summary_number(r, "frames"))) + "," +
         fixed(summary_number(r, "fps"), 2) + "," + fixed(summary_number(r, "tracker_fps"), 2) +
         "," + fixed(r.ms_median, 3) + "," + fixed(r.ms_p95, 3) + "," + fixed(r.ms_mean, 3) + "," +
         std::to_string(std::llround(summary_number(r, "global_activations"))) + "," +
         fixed(summary_number(r, "peak_rss_mb"), 1) + "\n";
}

// ms per frame (median) of global over local: how many times faster local mode is.
double speedup(const CompareRun& local, const CompareRun& global) {
  return local.ms_median > 0 ? global.ms_median / local.ms_median : 0.0;
}

int run_compare(const TrackCommand& cmd) {
  const stages::TrackerParams params = tracker_params(cmd);
  const bool camera =
      !cmd.input.empty() && std::all_of(cmd.input.begin(), cmd.input.end(),
                                        [](unsigned char c) { return std::isdigit(c); });
  if (camera) {
    throw UsageError("--compare needs a video file or an image folder: a camera (" + cmd.input +
                     ") would show each mode different frames");
  }
  {
    // Opened here only to check the input and --init before any child starts.
    stages::VideoSource source(cmd.input, cmd.source.params());
    if (params.init) {
      const cv::Rect2f frame(0.f, 0.f, static_cast<float>(source.size().width),
                             static_cast<float>(source.size().height));
      if ((*params.init & frame).area() <= 0.f) {
        throw UsageError("--init: the box " + cmd.init + " lies outside the " +
                         size_string(source.size()) + " frame");
      }
    }
  }
  std::error_code ec;
  if (fs::exists(cmd.compare_out, ec) && !fs::is_directory(cmd.compare_out, ec)) {
    throw Error("--compare-out: '" + cmd.compare_out + "' exists and is not a directory");
  }
  fs::create_directories(cmd.compare_out, ec);
  if (ec) throw Error("--compare-out: cannot create '" + cmd.compare_out + "': " + ec.message());
  const fs::path out_dir = cmd.compare_out;
  std::string temp = (out_dir / ".runs-XXXXXX").string();
  if (mkdtemp(temp.data()) == nullptr) {
    throw Error("--compare-out: cannot create a folder in '" + cmd.compare_out + "'");
  }
  struct RemoveDir {
    fs::path dir;
    ~RemoveDir() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } remove_temp{temp};

  SignalScope signals;
  const int patch = params.lk.patch;
  std::vector<CompareRun> main_runs;
  std::vector<std::pair<CompareRun, CompareRun>> patch_runs;
  try {
    for (const char* mode : {"local", "global"})
      main_runs.push_back(compare_run(cmd, mode, patch, out_dir, temp, mode));
    for (int p : cmd.compare_patches) {
      if (p == patch) {
        patch_runs.emplace_back(main_runs[0], main_runs[1]);
        continue;
      }
      const std::string stem = "patch" + std::to_string(p) + "_";
      patch_runs.emplace_back(compare_run(cmd, "local", p, temp, temp, stem + "local"),
                              compare_run(cmd, "global", p, temp, temp, stem + "global"));
    }
  } catch (const CompareInterrupted& stop) {
    std::cerr << "roiflow: error: interrupted by " << (stop.signal == SIGINT ? "SIGINT" : "SIGTERM")
              << " during the compare runs; no comparison written\n";
    return 128 + stop.signal;
  }
  const CompareRun& local = main_runs[0];
  const CompareRun& global = main_runs[1];

  // Files: compare.csv, compare.json, ms_per_frame.svg, patches.svg (with --compare-patches).
  std::string csv =
      "patch,mode,frames,fps,tracker_fps,ms_median,ms_p95,ms_mean,global_activations,"
      "peak_rss_mb\n";
  nlohmann::ordered_json doc;
  doc["input"] = cmd.input;
  doc["threads"] = cmd.lk.threads;
  doc["preset"] = cmd.lk.preset;
  doc["patch"] = patch;
  doc["local"] = compare_json(local);
  doc["global"] = compare_json(global);
  doc["speedup_median_ms"] = speedup(local, global);
  const double local_fps = summary_number(local, "tracker_fps");
  const double global_fps = summary_number(global, "tracker_fps");
  doc["speedup_tracker_fps"] = global_fps > 0 ? local_fps / global_fps : 0.0;
  csv += compare_csv_row(local) + compare_csv_row(global);
  doc["patches"] = nlohmann::ordered_json::array();
  for (const auto& [l, g] : patch_runs) {
    doc["patches"].push_back({{"patch", l.patch},
                              {"local", compare_json(l)},
                              {"global", compare_json(g)},
                              {"speedup_median_ms", speedup(l, g)}});
    csv += compare_csv_row(l) + compare_csv_row(g);
  }
  std::vector<std::string> written;
  const auto write_text = [&](const std::string& name, const std::string& text) {
    const std::string path = (out_dir / name).string();
    write_text_atomically(path, text);
    written.push_back(path);
  };
  write_text("compare.csv", csv);
  write_text("compare.json", doc.dump(2) + "\n");

  report::Plot frames_plot;
  frames_plot.title = "Tracker time per frame, local vs global (" +
                      fs::path(cmd.input).filename().string() + ", patch " + std::to_string(patch) +
                      ")";
  frames_plot.x_label = "frame index";
  report::PlotPanel& frames_panel = frames_plot.panels.emplace_back();
  frames_panel.y_label = "tracker time (ms per frame)";
  frames_panel.y_from_zero = true;
  for (const CompareRun* r : {&local, &global}) {
    report::PlotSeries s;
    s.name = r->mode + " (median " + fixed(r->ms_median, 2) + " ms)";
    for (std::size_t i = 0; i < r->ms.size(); ++i) {
      s.x.push_back(static_cast<double>(cmd.source.start + static_cast<long long>(i) + 1));
      s.y.push_back(r->ms[i]);
    }
    s.markers = r->ms.size() <= 60;
    frames_panel.series.push_back(std::move(s));
  }
  const std::string frames_svg = (out_dir / "ms_per_frame.svg").string();
  report::write_plot_svg(frames_svg, frames_plot);
  written.push_back(frames_svg);

  if (!patch_runs.empty()) {
    report::Plot plot;
    plot.title = "Tracker time vs patch size, local vs global (" +
                 fs::path(cmd.input).filename().string() + ")";
    plot.x_label = "patch size (px)";
    plot.panels.resize(2);  // references taken after the last resize stay valid
    report::PlotPanel& time = plot.panels[0];
    time.y_label = "tracker time (ms per frame, median)";
    time.y_from_zero = true;
    report::PlotPanel& ratio = plot.panels[1];
    ratio.y_label = "global / local time (x)";
    ratio.y_from_zero = true;
    report::PlotSeries l{"local", {}, {}}, g{"global", {}, {}}, r{"speed-up of local", {}, {}};
    for (const auto& [lr, gr] : patch_runs) {
      l.x.push_back(lr.patch);
      l.y.push_back(lr.ms_median);
      g.x.push_back(gr.patch);
      g.y.push_back(gr.ms_median);
      r.x.push_back(lr.patch);
      r.y.push_back(speedup(lr, gr));
    }
    time.series = {l, g};
    ratio.series = {r};
    const std::string path = (out_dir / "patches.svg").string();
    report::write_plot_svg(path, plot);
    written.push_back(path);
  }

  // The table.
  std::cout << "compare " << cmd.input << ": local vs global, patch " << patch << ", "
            << cmd.lk.threads << " threads, one mode after the other\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-7s %7s %8s %12s %10s %8s %8s %12s %9s\n", "mode", "frames",
                "fps", "tracker fps", "ms median", "ms p95", "ms mean", "global act.", "peak MiB");
  std::cout << line;
  const auto print_row = [&](const CompareRun& r) {
    std::snprintf(line, sizeof line, "%-7s %7lld %8.1f %12.1f %10.3f %8.3f %8.3f %12lld %9.1f\n",
                  r.mode.c_str(), std::llround(summary_number(r, "frames")),
                  summary_number(r, "fps"), summary_number(r, "tracker_fps"), r.ms_median, r.ms_p95,
                  r.ms_mean, std::llround(summary_number(r, "global_activations")),
                  summary_number(r, "peak_rss_mb"));
    std::cout << line;
  };
  print_row(local);
  print_row(global);
  std::cout << "local mode is " << fixed(speedup(local, global), 1)
            << "x faster than global (median ms per frame), "
            << fixed(doc["speedup_tracker_fps"].get<double>(), 1) << "x (tracker fps)\n";
  if (!patch_runs.empty()) {
    std::snprintf(line, sizeof line, "%6s %16s %16s %9s\n", "patch", "local ms median",
                  "global ms median", "speed-up");
    std::cout << line;
    for (const auto& [lr, gr] : patch_runs) {
      std::snprintf(line, sizeof line, "%6d %16.3f %16.3f %8.1fx\n", lr.patch, lr.ms_median,
                    gr.ms_median, speedup(lr, gr));
      std::cout << line;
    }
  }
  std::string list;
  for (const std::string& w : written)
    list += (list.empty() ? "" : ", ") + w;
  std::cout << "  wrote " << list << "\n  per-mode logs and summaries: "
            << (out_dir / "{local,global}.{csv,json}").string() << "\n";
  return 0;
}

// Every moving object (no --init, several, or --init-file): the multi-object graph.
int run_track_objects(const TrackCommand& cmd) {
  pipeline::MotRunOptions o;
  for (const std::string& text : cmd.inits) {
    const cv::Rect2f box = parse_box(text, "--init");
    o.params.known.push_back({static_cast<long long>(o.params.known.size()) + 1, box});
  }
  if (!cmd.init_file.empty()) {
    if (!cmd.inits.empty())
      throw UsageError("--init-file: give the targets either there or by --init");
    try {
      o.params.known = stages::read_known_targets(cmd.init_file);
    } catch (const Error& e) {
      throw UsageError(std::string("--init-file: ") + e.what());
    }
  }
  o.params.births = o.params.known.empty();
  o.params.lk = lk_params(cmd.lk);
  try {
    o.params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  if (!cmd.log.empty()) check_log_path(cmd.log);
  if (!cmd.mot.empty()) check_output_path(cmd.mot, "--mot");
  if (!cmd.out.video.empty()) check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_summary_path(cmd.out.summary);
  stages::VideoSource source(cmd.input, cmd.source.params());
  const cv::Rect2f frame(0.f, 0.f, static_cast<float>(source.size().width),
                         static_cast<float>(source.size().height));
  for (const stages::KnownTarget& k : o.params.known) {
    const cv::Rect2f inside = k.box & frame;
    if (inside.width < 2 || inside.height < 2)
      throw UsageError("target " + std::to_string(k.id) + " lies outside the " +
                       size_string(source.size()) + " frame");
  }
  o.log = cmd.log;
  o.mot = cmd.mot;
  o.video = cmd.out.video;
  o.threads = cmd.lk.threads;
  o.in_flight = cmd.source.in_flight;
  o.progress = cmd.out.progress;
  o.frame_hint = source.frame_count_hint();
  o.cancel = &g_cancel;
  SignalScope signals;
  pipeline::MotRun run =
      pipeline::track_objects([&] { return source.next(); }, source.size(), source.fps(), o);
  const Ending end = ending(run.report, &source.status());
  run.summary["input"] = source.description();
  run.summary["status"] = end.message.empty() ? source.status().message : end.message;
  std::vector<std::string> written;
  for (const std::string* path : {&cmd.log, &cmd.mot, &cmd.out.video})
    if (!path->empty()) written.push_back(*path);
  if (!cmd.out.summary.empty()) {
    write_text_atomically(cmd.out.summary, run.summary.dump(2) + "\n");
    written.push_back(cmd.out.summary);
  }
  print_track_summary("track " + source.description(), run.summary, written);
  std::cout << "  objects born " << run.summary.at("objects_born").get<long long>() << ", ended "
            << run.summary.at("objects_ended").get<long long>() << ", at most "
            << run.summary.at("most_objects").get<long long>() << " at once\n";
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

int run_track(TrackCommand& cmd) {
  cmd.init = cmd.inits.size() == 1 ? cmd.inits.front() : std::string();
  const bool objects = !cmd.compare && !cmd.single && cmd.mode == "local" &&
                       (cmd.inits.size() != 1 || !cmd.init_file.empty());
  if (objects) return run_track_objects(cmd);
  if (cmd.inits.size() > 1 || !cmd.init_file.empty())
    throw UsageError(
        "several targets (--init twice, --init-file) need --mode local without "
        "--single or --compare");
  if (!cmd.mot.empty()) throw UsageError("--mot needs the multi-object tracker (not --single)");
  if (cmd.compare) return run_compare(cmd);
  const stages::TrackerParams params = tracker_params(cmd);
  if (!cmd.log.empty()) check_log_path(cmd.log);
  if (!cmd.out.video.empty()) check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_summary_path(cmd.out.summary);

  stages::VideoSource source(cmd.input, cmd.source.params());
  check_init_inside(params, cmd.init, source.size());

  SignalScope signals;
  TrackRun run =
      track([&] { return source.next(); }, source.size(), source.fps(), source.frame_count_hint(),
            params, cmd.lk.threads, cmd.source.in_flight, cmd.log, cmd.out, false);
  const Ending end = ending(run.report, &source.status());
  run.summary["input"] = source.description();
  run.summary["status"] = end.message.empty() ? source.status().message : end.message;

  std::vector<std::string> written;
  if (!cmd.log.empty()) written.push_back(cmd.log);
  if (!cmd.out.video.empty()) written.push_back(cmd.out.video);
  if (!cmd.out.summary.empty()) {
    write_text_atomically(cmd.out.summary, run.summary.dump(2) + "\n");
    written.push_back(cmd.out.summary);
  }
  print_track_summary("track " + source.description(), run.summary, written);
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

void add_run_outputs(CLI::App& sub, RunOutputs& out, const std::string& video_help) {
  sub.add_option("--out", out.video, video_help)->type_name("VIDEO|DIR");
  sub.add_option("--summary", out.summary, "run summary (frames, fps per stage, ...) as JSON")
      ->type_name("JSON");
  sub.add_flag("!--no-progress", out.progress, "no progress bar on the terminal");
}

void add_source_options(CLI::App& sub, SourceOptions& source) {
  sub.add_option("--start", source.start, "index of the first frame to read")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--max-frames", source.max_frames, "stop after this many frames (0 = all)")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--in-flight", source.in_flight,
                 "frames decoded ahead and in the pipeline at most (0 = 2 x threads + 2)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--decode-threads", source.decode_threads,
                 "a video's FFmpeg decoder threads (0 = one up to 1280x720, where more cost more "
                 "than they give, else FFmpeg's choice)")
      ->check(CLI::Range(0, 64));
}

void add_track_command(CLI::App& app, TrackCommand& cmd, int& exit_code) {
  CLI::App* sub = app.add_subcommand(
      "track", "Track the moving object of a video with LK in a local region (paper's system)");
  sub->add_option("INPUT", cmd.input,
                  "video file, image-sequence folder (OTB img/), camera index, or "
                  "synthetic:N[:WxH] (a generated stream of N frames, for soak runs)")
      ->required();
  sub->add_option("--init", cmd.inits,
                  "a target's box in the first frame, x,y,w,h (OTB protocol); once: the "
                  "single-object tracker; repeated: those targets (ids 1, 2, ...); without it "
                  "every moving object is found and followed (fixed camera)")
      ->type_name("X,Y,W,H")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sub->add_option("--init-file", cmd.init_file, "known targets, one id,x,y,w,h line each")
      ->type_name("FILE");
  sub->add_option("--mot", cmd.mot,
                  "every object's boxes in MOTChallenge format (frame,id,x,y,w,h,conf,-1,-1,-1)")
      ->type_name("FILE");
  sub->add_flag("--single", cmd.single,
                "follow one object (the paper's single-object tracker) even without --init");
  sub->add_option("--roi", cmd.roi, "side of the local region in pixels")
      ->check(CLI::Range(8, 4096))
      ->capture_default_str();
  sub->add_option("--lk-patches", cmd.lk_patches,
                  "LK runs on the coarsest pyramid level where the object's shorter side still "
                  "spans this many LK patches, its flow upsampled (0 = always full resolution)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  sub->add_option("--mode", cmd.mode,
                  "local: LK in the local region, global fallback; global: the whole frame every "
                  "frame (the paper's baseline)")
      ->check(CLI::IsMember({"local", "global"}))
      ->capture_default_str();
  sub->add_option("--log", cmd.log, "track log, one line per frame (.csv or .json)")
      ->type_name("FILE");
  add_run_outputs(*sub, cmd.out, "annotated video (.mp4 .avi .mkv .mov) or a folder of PNG frames");
  add_source_options(*sub, cmd.source);
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  const std::string group = "Run-time comparison (paper Sec. 4.4-4.5, Fig. 12)";
  CLI::Option* compare =
      sub->add_flag("--compare", cmd.compare,
                    "run the input in local and in global mode (child processes, one after the "
                    "other) and report fps, ms per frame, global activations and peak memory")
          ->group(group);
  for (const char* name : {"--mode", "--log", "--out", "--summary"})
    compare->excludes(sub->get_option(name));
  sub->add_option("--compare-out", cmd.compare_out,
                  "folder for compare.csv/.json, ms_per_frame.svg, patches.svg and each mode's "
                  "log and summary (created if missing)")
      ->type_name("DIR")
      ->capture_default_str()
      ->needs(compare)
      ->group(group);
  sub->add_option("--compare-patches", cmd.compare_patches,
                  "also compare at these patch sizes, e.g. 6,10,14,20 (Fig. 12's axis)")
      ->type_name("LIST")
      ->delimiter(',')
      ->check(CLI::Range(3, 31))
      ->needs(compare)
      ->group(group);
  sub->callback([&cmd, &exit_code] { exit_code = run_track(cmd); });
}

// ---------------------------------------------------------------------------------------------
// roiflow dense

struct DenseCommand {
  LkOptions lk;
  std::string input;
  RunOutputs out;
  double max_motion = 0;
  SourceOptions source;
};

int run_dense(const DenseCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  if (cmd.out.video.empty()) throw UsageError("dense needs --out VIDEO|DIR");
  check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_summary_path(cmd.out.summary);

  stages::VideoSource source(cmd.input, cmd.source.params());
  stages::VideoSink video(cmd.out.video, source.fps(), source.size());
  const long long hint = source.frame_count_hint();
  report::Progress progress(std::cerr, hint > 1 ? hint - 1 : hint,
                            cmd.out.progress && report::Progress::stderr_is_terminal());

  SignalScope signals;
  report::RunStats stats;
  pipeline::GraphOptions options;
  options.threads = cmd.lk.threads;
  options.max_in_flight = cmd.source.in_flight;
  options.cancel = &g_cancel;
  options.stats = &stats;
  const float max_motion = static_cast<float>(cmd.max_motion > 0 ? cmd.max_motion : -1.0);
  const pipeline::RunReport report = pipeline::run_dense(
      [&] { return source.next(); }, params,
      {{"video",
        [&](const pipeline::FlowPair& p) {
          video.write(flow::flow_to_color(p.flow->flow, max_motion));
        }},
       {"progress", [&](const pipeline::FlowPair& p) { progress.update(p.seq + 1); }}},
      options);
  progress.finish();
  video.close();

  const Ending end = ending(report, &source.status());
  const nlohmann::ordered_json s = stats.to_json(report.wall_s);
  const long long pairs = std::max(0LL, report.frames - 1);
  const double flow_ms = stage_ms(s, "flow");
  nlohmann::ordered_json summary = {
      {"mode", "dense"},
      {"input", source.description()},
      {"frames", report.frames},
      {"pairs", pairs},
      {"fps", report.wall_s > 0 ? pairs / report.wall_s : 0.0},
      {"flow_ms_per_pair", pairs > 0 ? flow_ms / static_cast<double>(pairs) : 0.0},
      {"wall_s", report.wall_s},
      {"threads", cmd.lk.threads},
      {"preset", cmd.lk.preset},
      {"status", end.message.empty() ? source.status().message : end.message},
      {"peak_rss_mb", report::peak_rss_mb()},
      {"stages", s.at("stages")}};
  std::string written = cmd.out.video;
  if (!cmd.out.summary.empty()) {
    write_text_atomically(cmd.out.summary, summary.dump(2) + "\n");
    written += ", " + cmd.out.summary;
  }
  std::cout << "dense " << source.description() << ": " << pairs << " pairs in "
            << fixed(report.wall_s, 2) << " s, " << fixed(summary["fps"].get<double>(), 1)
            << " pairs/s, " << cmd.lk.threads << " threads\n  wrote " << written << "\n";
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

void add_dense_command(CLI::App& app, DenseCommand& cmd, int& exit_code) {
  CLI::App* sub = app.add_subcommand(
      "dense", "Colour-coded dense flow of every frame pair of a video, pairs in parallel");
  sub->add_option("INPUT", cmd.input, "video file, image-sequence folder, or camera index")
      ->required();
  add_run_outputs(*sub, cmd.out,
                  "the colour-coded flow: a video (.mp4 .avi .mkv .mov) or a folder of PNGs");
  sub->add_option("--max-motion", cmd.max_motion,
                  "flow magnitude (px) at full colour saturation; 0 = each pair's own maximum")
      ->check(CLI::Range(0.0, 1e4));
  add_source_options(*sub, cmd.source);
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([&cmd, &exit_code] { exit_code = run_dense(cmd); });
}

// ---------------------------------------------------------------------------------------------
// roiflow demo

struct DemoCommand {
  std::string dir = "out/demo";
  int frames = 150;
  int threads = 0;
  bool progress = true;
  int objects = 0;            // > 0: the multi-object traffic demo (mot_demo_command.cpp)
  bool frames_given = false;  // --frames was given (the traffic demo's default is 300)
};

int run_demo(const DemoCommand& cmd) {
  if (cmd.objects > 0) {
    return run_objects_demo(cmd.dir, cmd.objects, cmd.frames_given ? cmd.frames : 300,
                            cmd.threads > 0 ? cmd.threads : default_threads(), cmd.progress);
  }
  fs::create_directories(cmd.dir);
  eval::TrackingSceneParams scene_params;
  scene_params.frames = cmd.frames;
  const eval::TrackingScene scene(scene_params);
  const auto scene_source = [&scene]() {
    return [&scene, next = 0]() mutable -> std::optional<stages::Frame> {
      if (next >= scene.frames()) return std::nullopt;
      stages::Frame f;
      f.index = next;
      f.timestamp_s = next / 25.0;
      f.image = scene.render(next);
      cv::cvtColor(f.image, f.gray, cv::COLOR_BGR2GRAY);
      ++next;
      return f;
    };
  };
  const int threads = cmd.threads > 0 ? cmd.threads : default_threads();
  const std::string video = (fs::path(cmd.dir) / "demo.mp4").string();
  const std::string log = (fs::path(cmd.dir) / "track.csv").string();
  const std::string summary_path = (fs::path(cmd.dir) / "summary.json").string();
  const std::string truth_path = (fs::path(cmd.dir) / "groundtruth.txt").string();

  std::vector<cv::Rect2f> truth;
  std::string truth_text;
  for (int i = 0; i < scene.frames(); ++i) {
    truth.push_back(scene.box(i));
    const cv::Rect2f& b = truth.back();
    truth_text += fixed(b.x, 2) + "," + fixed(b.y, 2) + "," + fixed(b.width, 2) + "," +
                  fixed(b.height, 2) + "\n";
  }

  SignalScope signals;
  stages::TrackerParams params;  // paper defaults, no --init: the global treatment finds it
  RunOutputs out{video, "", cmd.progress};
  TrackRun local =
      track(scene_source(), scene.size(), 25.0, scene.frames(), params, threads, 0, log, out, true);
  if (local.report.cancelled) {
    std::cerr << "roiflow: error: interrupted\n";
    return 128 + g_signal.load();
  }
  params.mode = stages::TrackMode::Global;
  TrackRun global = track(scene_source(), scene.size(), 25.0, scene.frames(), params, threads, 0,
                          "", RunOutputs{"", "", false}, false);

  std::vector<cv::Rect2f> boxes;
  for (const eval::TrackRecord& r : local.records)
    boxes.push_back(r.box);
  const eval::OtbScore s = eval::score(boxes, truth);
  double centre_error = 0;
  int found_at = -1;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (found_at < 0 && boxes[i].area() > 0) found_at = static_cast<int>(i);
    if (found_at >= 0) centre_error += eval::center_error(boxes[i], truth[i]);
  }
  const long long tracked = found_at < 0 ? 0 : static_cast<long long>(boxes.size()) - found_at;
  if (tracked > 0) centre_error /= static_cast<double>(tracked);

  local.summary["input"] = "synthetic scene " + size_string(scene.size()) + ", " +
                           std::to_string(scene.frames()) + " frames";
  local.summary["score"] = {{"auc", s.auc},
                            {"precision20", s.precision20},
                            {"mean_iou", s.mean_iou},
                            {"mean_center_error", centre_error},
                            {"first_detection_frame", found_at + 1}};
  local.summary["global_mode"] = {{"tracker_fps", global.summary.at("tracker_fps")},
                                  {"fps", global.summary.at("fps")}};
  write_text_atomically(summary_path, local.summary.dump(2) + "\n");
  write_text_atomically(truth_path, truth_text);

  const double local_fps = local.summary.at("tracker_fps").get<double>();
  const double global_fps = global.summary.at("tracker_fps").get<double>();
  std::cout << "demo: synthetic fixed-camera scene " << size_string(scene.size()) << ", "
            << scene.frames() << " frames, the vehicle jumps " << fixed(scene_params.jump, 0)
            << " px at frame " << scene.jump_frame() + 1 << "\n";
  print_track_summary("  local mode", local.summary, {});
  std::cout << "  error vs the scene's boxes: success AUC " << fixed(s.auc, 3) << ", precision@20 "
            << fixed(s.precision20, 3) << ", mean IoU " << fixed(s.mean_iou, 3)
            << ", mean centre error " << fixed(centre_error, 2)
            << " px after the first detection (frame " << found_at + 1 << ")\n"
            << "  global mode (whole frame every frame): tracker " << fixed(global_fps, 1)
            << " fps; local mode is " << fixed(global_fps > 0 ? local_fps / global_fps : 0.0, 1)
            << "x faster\n"
            << "  wrote " << video << ", " << log << ", " << summary_path << ", " << truth_path
            << "\n";
  return 0;
}

void add_demo_command(CLI::App& app, DemoCommand& cmd, int& exit_code) {
  CLI::App* sub = app.add_subcommand(
      "demo",
      "Track a vehicle in a built-in synthetic video (no input needed) and print the error");
  sub->add_option("--dir", cmd.dir, "where the video, log and summary go")->capture_default_str();
  CLI::Option* frames =
      sub->add_option("--frames", cmd.frames, "length of the scene (with --objects: default 300)")
          ->check(CLI::Range(3, 100000))
          ->capture_default_str();
  sub->add_option("--objects", cmd.objects,
                  "track N vehicles of the synthetic traffic scene instead; writes mot.txt and "
                  "gt_mot.txt, prints MOTA and IDF1")
      ->check(CLI::Range(1, 256));
  sub->add_option("--threads", cmd.threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_flag("!--no-progress", cmd.progress, "no progress bar on the terminal");
  sub->callback([&cmd, &exit_code, frames] {
    cmd.frames_given = frames->count() > 0;
    exit_code = run_demo(cmd);
  });
}

}  // namespace

void add_video_commands(CLI::App& app, int& exit_code) {
  static TrackCommand track_cmd;
  static DenseCommand dense_cmd;
  static DemoCommand demo_cmd;
  add_track_command(app, track_cmd, exit_code);
  add_dense_command(app, dense_cmd, exit_code);
  add_demo_command(app, demo_cmd, exit_code);
}

}  // namespace roiflow::cli
