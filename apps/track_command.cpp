// roiflow track: one object through a video (pipeline::run_track_video); --compare runs it in
// local and in global mode (pipeline::run_compare).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/run_json.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

struct TrackCommand {
  LkOptions lk;
  std::string input;
  std::string init;
  int roi = 50;
  double lk_patches = stages::LocalTrackerParams{}.lk_patches;
  std::string mode = "local";
  std::string log;
  RunOutputs out;
  pipeline::SourceOptions source;
  int in_flight = 0;
  bool compare = false;  // --compare: local and global mode side by side
  std::string compare_out = "out/compare";
  std::vector<int> compare_patches;
};

// "x,y,w,h" (commas and/or spaces) with a positive size.
cv::Rect2f parse_box(const std::string& text, const std::string& option) {
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
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

// At least `min_side` x `min_side` pixels of the --init box inside the first frame (the
// tracker's own criterion is 2).
void check_init_inside(const stages::TrackerParams& params, const std::string& text, cv::Size size,
                       float min_side) {
  if (!params.init) return;
  const cv::Rect2f inside = *params.init & cv::Rect2f(0.f, 0.f, static_cast<float>(size.width),
                                                      static_cast<float>(size.height));
  if (inside.width < min_side || inside.height < min_side || inside.area() <= 0.f) {
    throw UsageError("--init: the box " + text + " lies outside the " + size_text(size) + " frame" +
                     (min_side > 0 ? " (less than 2x2 pixels of it inside)" : ""));
  }
}

pipeline::TrackRunOptions run_options(const TrackCommand& cmd) {
  pipeline::TrackRunOptions run;
  stages::TrackerParams& params = run.tracker;
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
  run.threads = cmd.lk.threads;
  run.max_in_flight = cmd.in_flight;
  run.log = cmd.log;
  run.video = cmd.out.video;
  run.progress = cmd.out.progress;
  run.cancel = cancel_flag();
  return run;
}

int run_compare(const TrackCommand& cmd) {
  pipeline::CompareOptions o;
  o.run = run_options(cmd);
  if (std::all_of(cmd.input.begin(), cmd.input.end(),
                  [](unsigned char c) { return std::isdigit(c); })) {
    throw UsageError("--compare needs a video file or an image folder: a camera (" + cmd.input +
                     ") would show each mode different frames");
  }
  o.input = cmd.input;
  o.source = cmd.source;
  o.preset = cmd.lk.preset;
  o.patches = cmd.compare_patches;
  o.out_dir = cmd.compare_out;
  // Opened here only to check the input and --init before any run starts.
  check_init_inside(o.run.tracker, cmd.init,
                    stages::VideoSource(cmd.input, pipeline::source_params(cmd.source)).size(),
                    0.f);
  SignalScope signals;
  const pipeline::CompareResult r = pipeline::run_compare(o);
  if (r.cancelled) {
    const int sig = caught_signal();
    std::cerr << "roiflow: error: interrupted by " << (sig == SIGINT ? "SIGINT" : "SIGTERM")
              << " during the compare runs; no comparison written\n";
    return 128 + sig;
  }
  const std::vector<std::string> written = pipeline::write_compare_files(r, o);
  std::cout << pipeline::compare_table(r, o) << "  wrote " << joined(written)
            << "\n  per-mode logs and summaries: "
            << (fs::path(o.out_dir) / "{local,global}.{csv,json}").string() << "\n";
  return 0;
}

int run_track(const TrackCommand& cmd) {
  if (cmd.compare) return run_compare(cmd);
  const pipeline::TrackRunOptions run = run_options(cmd);
  if (!cmd.log.empty()) {
    check_output_path(cmd.log, "--log");
    std::string ext = fs::path(cmd.log).extension().string();
    for (char& c : ext)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".csv" && ext != ".json") {
      throw UsageError("--log: '" + cmd.log + "' must end in .csv or .json");
    }
  }
  if (!cmd.out.video.empty()) check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_output_path(cmd.out.summary, "--summary");

  stages::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  check_init_inside(run.tracker, cmd.init, source.size(), 2.f);
  SignalScope signals;
  const pipeline::TrackSummary s = pipeline::run_track_video(source, run);
  const Ending end = ending(s.end, s.frames, s.status);
  nlohmann::ordered_json doc = pipeline::to_json(s);
  doc["input"] = s.input;
  doc["status"] = end.message.empty() ? s.status : end.message;

  std::vector<std::string> written;
  if (!cmd.log.empty()) written.push_back(cmd.log);
  if (!cmd.out.video.empty()) written.push_back(cmd.out.video);
  if (!cmd.out.summary.empty()) {
    write_text_atomically(cmd.out.summary, doc.dump(2) + "\n");
    written.push_back(cmd.out.summary);
  }
  print_track_summary("track " + s.input, s, written);
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

}  // namespace

void add_track_command(CLI::App& app, int& exit_code) {
  static TrackCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "track", "Track the moving object of a video with LK in a local region (paper's system)");
  sub->add_option("INPUT", cmd.input,
                  "video file, image-sequence folder (OTB img/), camera index, or "
                  "synthetic:N[:WxH] (a generated stream of N frames, for soak runs)")
      ->required();
  sub->add_option("--init", cmd.init,
                  "the target's box in the first frame, x,y,w,h (OTB protocol); without it the "
                  "global treatment finds the moving object")
      ->type_name("X,Y,W,H");
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
  add_source_options(*sub, cmd.source, cmd.in_flight);
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  const std::string group = "Run-time comparison (paper Sec. 4.4-4.5, Fig. 12)";
  CLI::Option* compare =
      sub->add_flag("--compare", cmd.compare,
                    "run the input in local and in global mode (one after the other) and report "
                    "fps, ms per frame, global activations and peak memory")
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
  sub->callback([&exit_code] { exit_code = run_track(cmd); });
}

}  // namespace roiflow::cli
