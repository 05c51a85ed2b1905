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
  std::string summary;
  pipeline::DenseRunOptions run;
  pipeline::SourceOptions source;
  std::string flow_format = "flo";
};

int run_dense(const DenseCommand& cmd) {
  pipeline::DenseRunOptions run = cmd.run;
  run.lk = lk_params(cmd.lk);
  run.flow_format = stages::flow_file_format_from_string(cmd.flow_format);
  if (run.video.empty() && run.flow_dir.empty()) {
    throw UsageError("dense needs --out VIDEO|DIR or --flow-out DIR");
  }
  if (!run.video.empty()) check_output_path(run.video, "--out");
  if (!cmd.summary.empty()) check_output_path(cmd.summary, "--summary");
  run.threads = cmd.lk.threads;
  run.cancel = pipeline::cancel_flag();

  stages::VideoSource source(cmd.input, pipeline::source_params(cmd.source));
  pipeline::SignalScope signals;
  pipeline::DenseSummary s = pipeline::run_dense_video(source, run);
  const pipeline::Ending end = pipeline::ending(s.end, s.frames, s.status);
  if (!end.message.empty()) s.status = end.message;
  std::string written = s.outputs;
  if (!cmd.summary.empty()) {
    write_text_atomically(cmd.summary, pipeline::to_json(s, cmd.lk.preset).dump(2) + "\n");
    written += ", " + cmd.summary;
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
  add_run_outputs(*sub, cmd.run.video, cmd.summary, cmd.run.progress,
                  "the colour-coded flow: a video (.mp4 .avi .mkv .mov) or a folder of PNGs");
  sub->add_option("--max-motion", cmd.run.max_motion,
                  "flow magnitude (px) at full colour saturation; 0 = each pair's own robust "
                  "maximum (the 99th percentile of its magnitudes)")
      ->check(CLI::Range(0.0, 1e4));
  sub->add_option("--flow-out", cmd.run.flow_dir,
                  "folder for the raw flow of every pair (000001.flo/.png: frame 1 -> 2)")
      ->type_name("DIR");
  sub->add_option("--flow-format", cmd.flow_format,
                  "raw flow files: flo (Middlebury, float) or kitti (16-bit PNG, 1/64 px)")
      ->check(CLI::IsMember({"flo", "kitti"}))
      ->capture_default_str();
  add_source_options(*sub, cmd.source, cmd.run.max_in_flight);
  cmd.lk.threads = pipeline::default_threads();
  add_lk_options(*sub, cmd.lk);
  sub->callback([&exit_code] { exit_code = run_dense(cmd); });
}

}  // namespace roiflow::cli
