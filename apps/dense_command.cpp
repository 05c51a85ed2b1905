// roiflow dense: the colour-coded flow of every frame pair of a video (pipeline::run_dense_video).
#include <iostream>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "pipeline/run_json.hpp"

namespace roiflow::cli {
namespace {

struct DenseCommand {
  LkOptions lk;
  std::string input;
  RunOutputs out;
  double max_motion = 0;
  pipeline::SourceOptions source;
  int in_flight = 0;
};

int run_dense(const DenseCommand& cmd) {
  pipeline::DenseRunOptions run;
  run.lk = lk_params(cmd.lk);
  if (cmd.out.video.empty()) throw UsageError("dense needs --out VIDEO|DIR");
  check_output_path(cmd.out.video, "--out");
  if (!cmd.out.summary.empty()) check_output_path(cmd.out.summary, "--summary");
  run.threads = cmd.lk.threads;
  run.max_in_flight = cmd.in_flight;
  run.video = cmd.out.video;
  run.max_motion = cmd.max_motion;
  run.progress = cmd.out.progress;
  run.cancel = cancel_flag();

  stages::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  SignalScope signals;
  pipeline::DenseSummary s = pipeline::run_dense_video(source, run);
  const Ending end = ending(s.end, s.frames, s.status);
  if (!end.message.empty()) s.status = end.message;
  std::string written = cmd.out.video;
  if (!cmd.out.summary.empty()) {
    write_text_atomically(cmd.out.summary, pipeline::to_json(s, cmd.lk.preset).dump(2) + "\n");
    written += ", " + cmd.out.summary;
  }
  std::cout << "dense " << s.input << ": " << s.pairs << " pairs in " << fixed(s.wall_s, 2)
            << " s, " << fixed(s.fps, 1) << " pairs/s, " << s.threads << " threads\n  wrote "
            << written << "\n";
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

}  // namespace

void add_dense_command(CLI::App& app, int& exit_code) {
  static DenseCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "dense", "Colour-coded dense flow of every frame pair of a video, pairs in parallel");
  sub->add_option("INPUT", cmd.input, "video file, image-sequence folder, or camera index")
      ->required();
  add_run_outputs(*sub, cmd.out,
                  "the colour-coded flow: a video (.mp4 .avi .mkv .mov) or a folder of PNGs");
  sub->add_option("--max-motion", cmd.max_motion,
                  "flow magnitude (px) at full colour saturation; 0 = each pair's own maximum")
      ->check(CLI::Range(0.0, 1e4));
  add_source_options(*sub, cmd.source, cmd.in_flight);
  cmd.lk.threads = default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([&exit_code] { exit_code = run_dense(cmd); });
}

}  // namespace roiflow::cli
