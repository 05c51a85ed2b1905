// roiflow track, dense and demo: the video subcommands, each a run of the tbb::flow graph.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.hpp"
#include "flow/color_code.hpp"
#include "flow/tracking_scene.hpp"
#include "pipeline/frame_graph.hpp"
#include "pipeline/tbb_executor.hpp"
#include "stages/annotate.hpp"
#include "stages/atomic_write.hpp"
#include "stages/otb_score.hpp"
#include "stages/progress.hpp"
#include "stages/run_stats.hpp"
#include "stages/track_log.hpp"
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

struct TrackCommand {
  LkOptions lk;
  std::string input;
  std::string init;
  int roi = 50;
  std::string mode = "local";
  std::string log;
  RunOutputs out;
  long long start = 0;
  long long max_frames = 0;
  int in_flight = 0;
};

struct TrackRun {
  pipeline::RunReport report;
  nlohmann::ordered_json summary;
  std::vector<stages::TrackRecord> records;  // kept when asked (the demo scores them)
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
  stages::Progress progress(std::cerr, frame_hint,
                            out.progress && stages::Progress::stderr_is_terminal());

  TrackRun run;
  long long lost = 0;
  std::vector<pipeline::TrackSink> sinks;
  sinks.push_back({"log", [&](const pipeline::TrackedFrame& f) {
                     const stages::TrackRecord r = f.output->record();
                     if (r.lost) ++lost;
                     if (log) log->write(r);
                     if (keep_records) run.records.push_back(r);
                   }});
  if (video) {
    sinks.push_back({"video", [&](const pipeline::TrackedFrame& f) {
                       video->write(stages::annotate_frame(f.frame->image, *f.output));
                     }});
  }
  sinks.push_back(
      {"progress", [&](const pipeline::TrackedFrame& f) { progress.update(f.seq + 1); }});

  stages::RunStats stats;
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
      {"stages", s.at("stages")}};
  return run;
}

stages::TrackerParams tracker_params(const TrackCommand& cmd) {
  stages::TrackerParams params;
  params.lk = lk_params(cmd.lk);
  params.mode = stages::track_mode_from_string(cmd.mode);
  params.roi = cmd.roi;
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

int run_track(const TrackCommand& cmd) {
  const stages::TrackerParams params = tracker_params(cmd);
  if (!cmd.log.empty()) check_log_path(cmd.log);
  if (!cmd.out.video.empty()) check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_summary_path(cmd.out.summary);

  stages::VideoSourceParams source_params;
  source_params.start = cmd.start;
  source_params.max_frames = cmd.max_frames;
  stages::VideoSource source(cmd.input, source_params);
  if (params.init) {
    const cv::Rect2f frame(0.f, 0.f, static_cast<float>(source.size().width),
                           static_cast<float>(source.size().height));
    if ((*params.init & frame).area() <= 0.f) {
      throw UsageError("--init: the box " + cmd.init + " lies outside the " +
                       size_string(source.size()) + " frame");
    }
  }

  SignalScope signals;
  TrackRun run =
      track([&] { return source.next(); }, source.size(), source.fps(), source.frame_count_hint(),
            params, cmd.lk.threads, cmd.in_flight, cmd.log, cmd.out, false);
  const Ending end = ending(run.report, &source.status());
  run.summary["input"] = source.description();
  run.summary["status"] = end.message.empty() ? source.status().message : end.message;

  std::vector<std::string> written;
  if (!cmd.log.empty()) written.push_back(cmd.log);
  if (!cmd.out.video.empty()) written.push_back(cmd.out.video);
  if (!cmd.out.summary.empty()) {
    stages::write_text_atomically(cmd.out.summary, run.summary.dump(2) + "\n");
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

void add_source_options(CLI::App& sub, long long& start, long long& max_frames, int& in_flight) {
  sub.add_option("--start", start, "index of the first frame to read")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--max-frames", max_frames, "stop after this many frames (0 = all)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--in-flight", in_flight,
                 "frames decoded ahead and in the pipeline at most (0 = 2 x threads + 2)")
      ->check(CLI::Range(0, 1024));
}

void add_track_command(CLI::App& app, TrackCommand& cmd, int& exit_code) {
  CLI::App* sub = app.add_subcommand(
      "track", "Track the moving object of a video with LK in a local region (paper's system)");
  sub->add_option("INPUT", cmd.input,
                  "video file, image-sequence folder (OTB img/), or camera index")
      ->required();
  sub->add_option("--init", cmd.init,
                  "the target's box in the first frame, x,y,w,h (OTB protocol); without it the "
                  "global treatment finds the moving object")
      ->type_name("X,Y,W,H");
  sub->add_option("--roi", cmd.roi, "side of the local region in pixels")
      ->check(CLI::Range(8, 4096))
      ->capture_default_str();
  sub->add_option("--mode", cmd.mode,
                  "local: LK in the local region, global fallback; global: the whole frame every "
                  "frame (the paper's baseline)")
      ->check(CLI::IsMember({"local", "global"}))
      ->capture_default_str();
  sub->add_option("--log", cmd.log, "track log, one line per frame (.csv or .json)")
      ->type_name("FILE");
  add_run_outputs(*sub, cmd.out, "annotated video (.mp4 .avi .mkv .mov) or a folder of PNG frames");
  add_source_options(*sub, cmd.start, cmd.max_frames, cmd.in_flight);
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([&cmd, &exit_code] { exit_code = run_track(cmd); });
}

// ---------------------------------------------------------------------------------------------
// roiflow dense

struct DenseCommand {
  LkOptions lk;
  std::string input;
  RunOutputs out;
  double max_motion = 0;
  long long start = 0;
  long long max_frames = 0;
  int in_flight = 0;
};

int run_dense(const DenseCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  if (cmd.out.video.empty()) throw UsageError("dense needs --out VIDEO|DIR");
  check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_summary_path(cmd.out.summary);

  stages::VideoSourceParams source_params;
  source_params.start = cmd.start;
  source_params.max_frames = cmd.max_frames;
  stages::VideoSource source(cmd.input, source_params);
  stages::VideoSink video(cmd.out.video, source.fps(), source.size());
  const long long hint = source.frame_count_hint();
  stages::Progress progress(std::cerr, hint > 1 ? hint - 1 : hint,
                            cmd.out.progress && stages::Progress::stderr_is_terminal());

  SignalScope signals;
  stages::RunStats stats;
  pipeline::GraphOptions options;
  options.threads = cmd.lk.threads;
  options.max_in_flight = cmd.in_flight;
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
      {"stages", s.at("stages")}};
  std::string written = cmd.out.video;
  if (!cmd.out.summary.empty()) {
    stages::write_text_atomically(cmd.out.summary, summary.dump(2) + "\n");
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
  add_source_options(*sub, cmd.start, cmd.max_frames, cmd.in_flight);
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
};

int run_demo(const DemoCommand& cmd) {
  fs::create_directories(cmd.dir);
  flow::TrackingSceneParams scene_params;
  scene_params.frames = cmd.frames;
  const flow::TrackingScene scene(scene_params);
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
  for (const stages::TrackRecord& r : local.records)
    boxes.push_back(r.box);
  const stages::OtbScore s = stages::score(boxes, truth);
  double centre_error = 0;
  int found_at = -1;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (found_at < 0 && boxes[i].area() > 0) found_at = static_cast<int>(i);
    if (found_at >= 0) centre_error += stages::center_error(boxes[i], truth[i]);
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
  stages::write_text_atomically(summary_path, local.summary.dump(2) + "\n");
  stages::write_text_atomically(truth_path, truth_text);

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
  sub->add_option("--frames", cmd.frames, "length of the scene")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  sub->add_option("--threads", cmd.threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_flag("!--no-progress", cmd.progress, "no progress bar on the terminal");
  sub->callback([&cmd, &exit_code] { exit_code = run_demo(cmd); });
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
