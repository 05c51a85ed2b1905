// roiflow dense: the colour-coded flow of every frame pair of a video (pipeline::run_dense_video).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/run_json.hpp"

namespace roiflow::cli {

void add_dense_command(CLI::App& app, int& exit_code) {
  static LkOptions lk;
  static std::string input, summary, flow_format = "flo";
  static pipeline::DenseRunOptions run;
  static pipeline::SourceOptions source;
  CLI::App* sub = app.add_subcommand(
      "dense", "Colour-coded dense flow of every frame pair of a video, pairs in parallel");
  sub->add_option("INPUT", input, "video file, image-sequence folder, or camera index")->required();
  add_run_outputs(*sub, run.video, summary, run.progress,
                  "the colour-coded flow: a video (.mp4 .avi .mkv .mov) or a folder of PNGs");
  sub->add_option("--max-motion", run.max_motion,
                  "flow magnitude (px) at full colour saturation; 0 = each pair's 99th "
                  "percentile of its magnitudes")
      ->check(CLI::Range(0.0, 1e4));
  sub->add_option("--flow-out", run.flow_dir, "folder for the raw flow of every pair (000001.flo)")
      ->type_name("DIR");
  sub->add_option("--flow-format", flow_format,
                  "raw flow files: flo (Middlebury, float) or kitti (16-bit PNG, 1/64 px)")
      ->check(CLI::IsMember({"flo", "kitti"}))
      ->capture_default_str();
  add_source_options(*sub, source, run.max_in_flight);
  lk.threads = pipeline::default_threads();
  add_lk_options(*sub, lk);
  sub->callback([&exit_code] {
    pipeline::DenseRunOptions o = run;
    o.lk = lk_params(lk);
    o.threads = lk.threads;
    o.flow_format = video::flow_file_format_from_string(flow_format);
    if (o.video.empty() && o.flow_dir.empty()) {
      throw UsageError("dense needs --out VIDEO|DIR or --flow-out DIR");
    }
    if (!o.video.empty()) check_output_path(o.video, "--out");
    if (!summary.empty()) check_output_path(summary, "--summary");
    o.cancel = pipeline::cancel_flag();
    video::VideoSource video(input, pipeline::source_params(source));
    pipeline::SignalScope signals;
    pipeline::DenseSummary s = pipeline::run_dense_video(video, o);
    const pipeline::Ending end = pipeline::ending(s.end, s.frames, s.status);
    if (!end.message.empty()) s.status = end.message;
    std::cout << pipeline::finish_run(summary, pipeline::to_json(s, lk.preset),
                                      pipeline::summary_text(s), {s.outputs});
    exit_code = run_end(end);
  });
}

}  // namespace roiflow::cli
