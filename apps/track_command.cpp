// roiflow track: every moving object, or the --init targets (pipeline::track_objects_video); one
// with --single or one --init (pipeline::run_track_video, --compare: pipeline::run_compare).
#include <iostream>

#include "cli_common.hpp"
#include "eval/otb_score.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/mot_run.hpp"
#include "pipeline/run_json.hpp"

namespace roiflow::cli {
namespace {

struct TrackCommand {
  LkOptions lk;
  std::string input, init_file, mot, summary, mode = "local";  // --init-file, --mot, ...
  std::vector<std::string> inits;                              // every --init
  bool single = false, compare = false;  // --single: one object even without --init
  pipeline::TrackRunOptions run;         // --roi, --lk-patches, --log, --out, --in-flight, ...
  pipeline::SourceOptions source;
  pipeline::CompareOptions comparison;  // --compare-out, --compare-patches
};

// Every moving object, or the known targets: the multi-object graph.
int run_objects(const TrackCommand& cmd) {
  pipeline::MotRunOptions o;
  o.params.known = pipeline::known_targets(cmd.inits, cmd.init_file);
  o.params.births = o.params.known.empty();
  o.params.lk = lk_params(cmd.lk);
  as_usage([&] { o.params.validate(); });
  o.log = cmd.run.log, o.mot = cmd.mot, o.video = cmd.run.video;
  pipeline::check_track_outputs(o.log, o.video, cmd.summary, o.mot);
  o.threads = cmd.lk.threads, o.in_flight = cmd.run.max_in_flight, o.progress = cmd.run.progress;
  o.cancel = pipeline::cancel_flag();
  video::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  pipeline::SignalScope signals;
  const pipeline::MotRun r = pipeline::track_objects_video(source, o);
  const std::string what = "track " + source.description();
  std::cout << pipeline::finish_run(cmd.summary, r.summary,
                                    pipeline::objects_summary_text(what, r.summary),
                                    {o.log, o.mot, o.video});
  return run_end(pipeline::ending(r.end, r.report.frames, source.status().message));
}

// One object (the paper's tracker); with --compare in local and in global mode.
int run_single(const TrackCommand& cmd) {
  pipeline::TrackRunOptions run = cmd.run;
  run.tracker.lk = lk_params(cmd.lk);
  run.tracker.mode = tracking::track_mode_from_string(cmd.mode);
  if (!cmd.inits.empty()) {
    as_usage([&] { run.tracker.init = eval::parse_box(cmd.inits.front()); }, "--init: ");
  }
  as_usage([&] { run.tracker.validate(); });
  run.threads = cmd.lk.threads;
  run.cancel = pipeline::cancel_flag();
  if (cmd.compare) {
    pipeline::CompareOptions o = cmd.comparison;
    o.run = run, o.input = cmd.input, o.source = cmd.source, o.preset = cmd.lk.preset;
    pipeline::SignalScope signals;
    const pipeline::CompareResult r = pipeline::run_compare(o);
    if (!r.cancelled) std::cout << pipeline::compare_text(r, o, write_compare_files(r, o));
    return run_end(pipeline::compare_ending(r));
  }
  pipeline::check_track_outputs(run.log, run.video, cmd.summary);
  video::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  pipeline::SignalScope signals;
  const pipeline::TrackSummary s = pipeline::run_track_video(source, run);
  const pipeline::Ending end = pipeline::ending(s.end, s.frames, s.status);
  std::cout << pipeline::finish_run(cmd.summary, pipeline::summary_json(s, end),
                                    pipeline::summary_text("track " + s.input, s),
                                    {run.log, run.video});
  return run_end(end);
}

int run_track(const TrackCommand& cmd) {
  const bool several = cmd.inits.size() > 1 || !cmd.init_file.empty();
  if (!cmd.compare && !cmd.single && cmd.mode == "local" && (several || cmd.inits.empty())) {
    return run_objects(cmd);
  }
  if (several) {
    throw UsageError(
        "several targets (--init twice, --init-file) need --mode local without "
        "--single or --compare");
  }
  if (!cmd.mot.empty()) {
    throw UsageError(
        "--mot needs the multi-object tracker (not --single, --mode global or --compare)");
  }
  return run_single(cmd);
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
  sub->add_option("--init-file", cmd.init_file, "known targets, one id,x,y,w,h line each");
  sub->add_option("--mot", cmd.mot, "every object's boxes, MOTChallenge format");
  sub->add_flag("--single", cmd.single, "follow one object (the paper's tracker) without --init");
  add_tracker_options(*sub, cmd.run.tracker, &cmd.mode);
  sub->add_option("--log", cmd.run.log, "track log, one line per frame (.csv or .json)");
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
                  "folder for compare.csv/.json, the plots and each mode's log and summary")
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
