// roiflow flow: dense flow of one image pair (or a synthetic one) to a .flo file.
#include <iostream>

#include "cli_common.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {

void add_flow_command(CLI::App& app, int& /*exit_code*/) {
  static const cv::Size kSyntheticSize{640, 480};
  static LkOptions lk;
  static std::string frame0, frame1, scene, ground_truth;  // scene: --synthetic
  static pipeline::FlowFiles files;                        // -o, --color, --legend
  CLI::App* sub = app.add_subcommand(
      "flow", "Dense flow of one image pair (or a built-in synthetic pair) to a .flo file");
  sub->add_option("A", frame0, "frame t (read as 8-bit gray)")->type_name("IMAGE");
  sub->add_option("B", frame1, "frame t+1")->type_name("IMAGE");
  std::vector<std::string> scenes;
  for (eval::SceneKind kind : eval::synthetic_scene_kinds())
    scenes.emplace_back(eval::to_string(kind));
  sub->add_option("--synthetic", scene,
                  "use a built-in " + size_text(kSyntheticSize) +
                      " pair with exact ground truth instead of A B, and print the error")
      ->type_name("SCENE")
      ->expected(0, 1)
      ->default_str(eval::to_string(eval::SceneKind::MovingObject))
      ->check(CLI::IsMember(scenes));
  sub->add_option("-o,--output", files.flo, "the flow, Middlebury .flo")->required();
  sub->add_option("--color", files.color,
                  "the flow in Middlebury colours, saturated at the 99th percentile of its "
                  "magnitudes (with --gt: at the truth's largest)");
  sub->add_option("--legend", files.legend, "the colour wheel, as a legend");
  sub->add_option("--gt", ground_truth, "ground-truth flow: print the error against it");
  add_lk_options(*sub, lk);
  sub->callback([] {
    const flow::LkParams params = lk_params(lk);
    files.check();
    const eval::FlowInput in =
        eval::flow_input(frame0, frame1, ground_truth, scene, kSyntheticSize);
    const pipeline::FlowRun r = pipeline::run_flow(in, params, lk.threads);
    std::cout << pipeline::flow_text(in, r, pipeline::write_flow_files(files, in, r));
  });
}

}  // namespace roiflow::cli
