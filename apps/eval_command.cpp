// roiflow eval: dense flow error and time over pairs with ground truth (pipeline::run_eval).
#include <iostream>

#include "cli_common.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {

void add_eval_command(CLI::App& app, int& /*exit_code*/) {
  static LkOptions lk;
  static std::string dir, layout = "auto";
  static std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  static std::vector<std::string> exclude_masks;
  static eval::FindOptions find;     // --pass, --scene, --max-pairs
  static pipeline::EvalOutputs out;  // --format, -o, --report
  CLI::App* sub = app.add_subcommand(
      "eval",
      "Dense flow error (AAE, EPE, R1, R3, KITTI Fl) and time over pairs with ground truth");
  const auto [d, pair] = add_pair_inputs(
      *sub, dir, pairs, "Middlebury, MPI-Sintel or KITTI tree, found by its layout (docs/CLI.md)");
  sub->add_option("--exclude-mask", exclude_masks, "pixels not scored (non-zero), one per --pair")
      ->needs(pair);
  sub->add_option("--layout", layout, "layout of DIR (auto: found from its folders)")
      ->check(CLI::IsMember({"auto", "middlebury", "sintel", "kitti"}))
      ->capture_default_str()
      ->needs(d);
  sub->add_option("--pass", find.pass,
                  "Sintel pass (auto: per scene, the first of clean, final, albedo found)")
      ->check(CLI::IsMember({"auto", "clean", "final", "albedo"}))
      ->capture_default_str()
      ->needs(d);
  sub->add_option("--scene", find.scene, "only this scene of DIR (alley_1, Venus, 000042)")
      ->needs(d);
  sub->add_option("--max-pairs", find.max_pairs, "at most N pairs of DIR, evenly spaced (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->needs(d);
  sub->add_option("--format", out.format, "output format")
      ->check(CLI::IsMember({"table", "csv", "json"}))
      ->capture_default_str();
  sub->add_option("-o,--output", out.output, "write the results to FILE instead of stdout");
  sub->add_option("--report", out.report, "also write an HTML report (flows, error maps, metrics)");
  add_lk_options(*sub, lk);
  sub->callback([] {
    const flow::LkParams params = lk_params(lk);
    out.check();
    std::vector<std::string> skipped;
    eval::FindOptions f = find;
    f.layout = eval::parse_layout(layout);
    const auto selected = eval::select_pairs(dir, f, pairs, exclude_masks, &skipped);
    // Partial downloads are evaluated as they are, the gaps said once on stderr (so that CSV
    // and JSON on stdout stay machine-readable).
    if (!skipped.empty()) std::cerr << "roiflow: " << eval::skipped_line(skipped) << "\n";
    pipeline::EvalOutputs o = out;
    o.title = "roiflow eval " + (dir.empty() ? std::string("--pair") : dir);
    std::cout << pipeline::run_eval(selected, params, lk.preset, lk.threads, o);
  });
}

}  // namespace roiflow::cli
