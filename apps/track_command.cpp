// roiflow track: every moving object of a fixed-camera video, or the --init targets
// (pipeline::track_objects_video); one object with --single or one --init
// (pipeline::run_track_video); --compare runs that in local and in global mode.
#include <csignal>
#include <filesystem>
#include <iostream>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "eval/otb_score.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/mot_run.hpp"
#include "pipeline/run_json.hpp"
#include "stages/track_log_sink.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

struct TrackCommand {
  LkOptions lk;
  std::string input;
  std::vector<std::string> inits;  // every --init
  std::string init_file, mot;      // --init-file, --mot
  bool single = false;             // --single: one object even without --init
  std::string mode = "local";
  std::string summary;
  pipeline::TrackRunOptions run;  // --roi, --lk-patches, --log, --out, --in-flight, ...
  pipeline::SourceOptions source;
  bool compare = false;                 // --compare: local and global mode side by side
  pipeline::CompareOptions comparison;  // --compare-out, --compare-patches
};

pipeline::TrackRunOptions run_options(const TrackCommand& cmd) {
  pipeline::TrackRunOptions run = cmd.run;
  stages::TrackerParams& params = run.tracker;
  params.lk = lk_params(cmd.lk);
  params.mode = stages::track_mode_from_string(cmd.mode);
  try {
    if (!cmd.inits.empty()) params.init = eval::parse_box(cmd.inits.front());
  } catch (const Error& e) {
    throw UsageError(std::string("--init: ") + e.what());
  }
  try {
    params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  run.threads = cmd.lk.threads;
  run.cancel = pipeline::cancel_flag();
  return run;
}

int run_compare(const TrackCommand& cmd) {
  pipeline::CompareOptions o = cmd.comparison;
  o.run = run_options(cmd);
  o.input = cmd.input;
  o.source = cmd.source;
  o.preset = cmd.lk.preset;
  pipeline::SignalScope signals;
  const pipeline::CompareResult r = pipeline::run_compare(o);
  if (r.cancelled) {
    const int sig = pipeline::caught_signal();
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

int finish(const std::string& summary, nlohmann::ordered_json& doc, const std::string& text,
           std::vector<std::string> written, const pipeline::Ending& end) {
  if (!summary.empty()) {
    write_text_atomically(summary, doc.dump(2) + "\n");
    written.push_back(summary);
  }
  std::cout << text;
  if (!written.empty()) std::cout << "  wrote " << joined(written) << "\n";
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

int run_objects(const TrackCommand& cmd) {
  pipeline::MotRunOptions o;
  o.params.known = pipeline::known_targets(cmd.inits, cmd.init_file);
  o.params.births = o.params.known.empty();
  o.params.lk = lk_params(cmd.lk);
  try {
    o.params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  o.log = cmd.run.log, o.mot = cmd.mot, o.video = cmd.run.video;
  if (!o.log.empty()) stages::check_track_log_path(o.log, "--log");
  for (const auto& [path, name] :
       {std::pair{o.mot, "--mot"}, {o.video, "--out"}, {cmd.summary, "--summary"}})
    if (!path.empty()) check_output_path(path, name);
  o.threads = cmd.lk.threads, o.in_flight = cmd.run.max_in_flight, o.progress = cmd.run.progress;
  o.cancel = pipeline::cancel_flag();
  stages::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  pipeline::SignalScope signals;
  pipeline::MotRun r = pipeline::track_objects_video(source, o);
  std::vector<std::string> written;
  for (const std::string* path : {&o.log, &o.mot, &o.video})
    if (!path->empty()) written.push_back(*path);
  return finish(cmd.summary, r.summary,
                pipeline::objects_summary_text("track " + source.description(), r.summary), written,
                pipeline::ending(r.end, r.report.frames, source.status().message));
}

int run_track(const TrackCommand& cmd) {
  const bool several = cmd.inits.size() > 1 || !cmd.init_file.empty();
  if (!cmd.compare && !cmd.single && cmd.mode == "local" && (several || cmd.inits.empty()))
    return run_objects(cmd);
  if (several)
    throw UsageError(
        "several targets (--init twice, --init-file) need --mode local without --single or "
        "--compare");
  if (!cmd.mot.empty())
    throw UsageError(
        "--mot needs the multi-object tracker (not --single, --mode global or --compare)");
  if (cmd.compare) return run_compare(cmd);
  const pipeline::TrackRunOptions run = run_options(cmd);
  if (!run.log.empty()) stages::check_track_log_path(run.log, "--log");
  if (!run.video.empty()) check_output_path(run.video, "--out");
  if (!cmd.summary.empty()) check_output_path(cmd.summary, "--summary");

  stages::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  pipeline::SignalScope signals;
  const pipeline::TrackSummary s = pipeline::run_track_video(source, run);
  const pipeline::Ending end = pipeline::ending(s.end, s.frames, s.status);
  nlohmann::ordered_json doc = pipeline::to_json(s);
  doc["input"] = s.input;
  doc["status"] = end.message.empty() ? s.status : end.message;

  std::vector<std::string> written;
  if (!run.log.empty()) written.push_back(run.log);
  if (!run.video.empty()) written.push_back(run.video);
  return finish(cmd.summary, doc, pipeline::summary_text("track " + s.input, s), written, end);
}

}  // namespace

void add_track_command(CLI::App& app, int& exit_code) {
  static TrackCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "track", "Track every moving object of a video (or one) with LK in local regions");
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
  sub->add_option("--mot", cmd.mot, "every object's boxes, MOTChallenge format")->type_name("FILE");
  sub->add_flag("--single", cmd.single, "follow one object (the paper's tracker) without --init");
  sub->add_option("--roi", cmd.run.tracker.roi, "side of the local region in pixels")
      ->check(CLI::Range(8, 4096))
      ->capture_default_str();
  sub->add_option("--lk-patches", cmd.run.tracker.local.lk_patches,
                  "LK runs on the coarsest pyramid level where the object's shorter side still "
                  "spans this many LK patches, its flow upsampled (0 = always full resolution)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  sub->add_option("--mode", cmd.mode,
                  "local: LK in the local region, global fallback; global: the whole frame every "
                  "frame (the paper's baseline)")
      ->check(CLI::IsMember({"local", "global"}))
      ->capture_default_str();
  sub->add_option("--log", cmd.run.log, "track log, one line per frame (.csv or .json)")
      ->type_name("FILE");
  add_run_outputs(*sub, cmd.run.video, cmd.summary, cmd.run.progress,
                  "annotated video (.mp4 .avi .mkv .mov) or a folder of PNG frames");
  add_source_options(*sub, cmd.source, cmd.run.max_in_flight);
  cmd.lk.threads = pipeline::default_threads();
  add_lk_options(*sub, cmd.lk);
  const std::string group = "Run-time comparison (paper Sec. 4.4-4.5, Fig. 12)";
  CLI::Option* compare =
      sub->add_flag("--compare", cmd.compare,
                    "run the input in local and in global mode (one after the other) and report "
                    "fps, ms per frame, global activations and peak memory")
          ->group(group);
  for (const char* name : {"--mode", "--log", "--out", "--summary"})
    compare->excludes(sub->get_option(name));
  cmd.comparison.out_dir = "out/compare";
  sub->add_option("--compare-out", cmd.comparison.out_dir,
                  "folder for compare.csv/.json, ms_per_frame.svg, patches.svg and each mode's "
                  "log and summary (created if missing)")
      ->type_name("DIR")
      ->capture_default_str()
      ->needs(compare)
      ->group(group);
  sub->add_option("--compare-patches", cmd.comparison.patches,
                  "also compare at these patch sizes, e.g. 6,10,14,20 (Fig. 12's axis)")
      ->type_name("LIST")
      ->delimiter(',')
      ->check(CLI::Range(3, 31))
      ->needs(compare)
      ->group(group);
  sub->callback([&exit_code] { exit_code = run_track(cmd); });
}

}  // namespace roiflow::cli
