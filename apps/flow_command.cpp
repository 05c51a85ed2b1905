// roiflow flow: dense flow of one image pair (or a synthetic one) to a .flo file.
#include <iostream>

#include "cli_common.hpp"
#include "eval/flo_io.hpp"
#include "eval/flow_input.hpp"
#include "eval/image_io.hpp"
#include "flow/color_code.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {
namespace {

const cv::Size kSyntheticSize{640, 480};

struct FlowCommand {
  LkOptions lk;
  std::string frame0;
  std::string frame1;
  std::string scene;  // set by --synthetic
  std::string output;
  std::string color;
  std::string legend;
  std::string ground_truth;
};

void run_flow(const FlowCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  const bool synthetic = !cmd.scene.empty();
  if (synthetic && !cmd.frame0.empty()) {
    throw UsageError("give either two images A B or --synthetic, not both");
  }
  if (synthetic && !cmd.ground_truth.empty()) {
    throw UsageError("--gt: a --synthetic scene brings its own ground truth");
  }
  if (!synthetic && cmd.frame1.empty()) {
    throw UsageError("flow needs two images A B, or --synthetic [scene]");
  }
  check_output_path(cmd.output, "-o");
  if (!cmd.color.empty()) eval::check_image_output(cmd.color, "--color");
  if (!cmd.legend.empty()) eval::check_image_output(cmd.legend, "--legend");
  const eval::FlowInput in = synthetic
                                 ? eval::synthetic_flow_input(cmd.scene, kSyntheticSize)
                                 : eval::read_flow_input(cmd.frame0, cmd.frame1, cmd.ground_truth);

  const pipeline::FlowRun r = pipeline::run_flow(in, params, cmd.lk.threads);
  // Scored before writing so that a failure here leaves no output behind.
  if (r.errors && r.errors->pixels == 0) {
    throw Error("--gt: '" + cmd.ground_truth + "' is unknown everywhere");
  }
  std::vector<std::string> written{cmd.output};
  eval::write_flo(cmd.output, r.flow);
  if (!cmd.color.empty()) {
    // Against a ground truth, the truth's largest vector saturates, so the two pictures compare.
    const float scale = in.truth.empty() ? -1.f : flow::max_magnitude(in.truth);
    eval::write_image_atomically(written.emplace_back(cmd.color),
                                 flow::flow_to_color(r.flow, scale));
  }
  if (!cmd.legend.empty()) {
    eval::write_image_atomically(written.emplace_back(cmd.legend), flow::color_wheel_legend());
  }
  std::cout << "flow " << size_text(in.frame0.size()) << " (" << in.source
            << "): " << fixed(r.ms, 2) << " ms, wrote " << joined(written) << "\n";
  if (r.errors) std::cout << "error vs ground truth: " << eval::errors_text(*r.errors) << "\n";
}

}  // namespace

void add_flow_command(CLI::App& app, int& /*exit_code*/) {
  static FlowCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "flow", "Dense flow of one image pair (or a built-in synthetic pair) to a .flo file");
  sub->add_option("A", cmd.frame0, "frame t (read as 8-bit gray)")->type_name("IMAGE");
  sub->add_option("B", cmd.frame1, "frame t+1")->type_name("IMAGE");
  std::vector<std::string> scenes;
  for (eval::SceneKind kind : eval::synthetic_scene_kinds())
    scenes.emplace_back(eval::to_string(kind));
  sub->add_option("--synthetic", cmd.scene,
                  "use a built-in " + size_text(kSyntheticSize) +
                      " pair with exact ground truth instead of A B, and print the error")
      ->type_name("SCENE")
      ->expected(0, 1)
      ->default_str(eval::to_string(eval::SceneKind::MovingObject))
      ->check(CLI::IsMember(scenes));
  sub->add_option("-o,--output", cmd.output, "the flow, Middlebury .flo")
      ->type_name("FLO")
      ->required();
  sub->add_option("--color", cmd.color,
                  "the flow in Middlebury colour coding, saturated at the 99th percentile of its "
                  "magnitudes (with --gt: at the truth's largest)")
      ->type_name("IMAGE");
  sub->add_option("--legend", cmd.legend, "the colour wheel, as a legend")->type_name("IMAGE");
  sub->add_option("--gt", cmd.ground_truth, "ground-truth flow: print the error against it")
      ->type_name("FLO");
  add_lk_options(*sub, cmd.lk);
  sub->callback([] { run_flow(cmd); });
}

}  // namespace roiflow::cli
