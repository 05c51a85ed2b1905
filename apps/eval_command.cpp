// roiflow eval: dense flow error and time over pairs with ground truth (eval::evaluate_pair).
#include <iostream>
#include <optional>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "eval/flow_input.hpp"
#include "pipeline/eval_runs.hpp"

namespace roiflow::cli {
namespace {

struct EvalCommand {
  LkOptions lk;
  std::string dir;
  std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  std::vector<std::string> exclude_masks;
  std::string layout = "auto";
  eval::FindOptions find;  // --pass, --scene, --max-pairs
  std::string format = "table";
  std::string output;
  std::string report;
};

void run_eval(const EvalCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  if (!cmd.output.empty()) check_output_path(cmd.output, "-o");
  if (!cmd.report.empty()) check_output_path(cmd.report, "--report");
  std::vector<std::string> skipped;
  eval::FindOptions find = cmd.find;
  find.layout = eval::parse_layout(cmd.layout);
  const std::vector<eval::EvalPair> pairs =
      eval::select_pairs(cmd.dir, find, cmd.pairs, cmd.exclude_masks, &skipped);
  // Partial downloads are evaluated as they are, and the gaps said once, on stderr so that
  // CSV and JSON on stdout stay machine-readable.
  if (!skipped.empty()) std::cerr << "roiflow: " << eval::skipped_line(skipped) << "\n";

  std::optional<report::HtmlReport> report;
  if (!cmd.report.empty()) {
    report.emplace("roiflow eval " + (cmd.dir.empty() ? std::string("--pair") : cmd.dir),
                   cmd.lk.preset, params);
  }
  const std::vector<eval::EvalRow> rows =
      pipeline::run_eval(pairs, params, cmd.lk.threads, report ? &*report : nullptr);

  const std::string text = cmd.format == "csv"    ? eval::format_csv(rows)
                           : cmd.format == "json" ? eval::format_json(rows, cmd.lk.preset, params)
                                                  : eval::format_table(rows);
  if (report) report->write(cmd.report);
  if (cmd.output.empty()) {
    std::cout << text;
  } else {
    write_text_atomically(cmd.output, text);
    std::cout << "evaluated " << rows.size() << " pairs, wrote " << cmd.output << "\n";
  }
  if (report) std::cout << "wrote report " << cmd.report << "\n";
}

}  // namespace

void add_eval_command(CLI::App& app, int& /*exit_code*/) {
  static EvalCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "eval",
      "Dense flow error (AAE, EPE, R1, R3, KITTI Fl) and time over pairs with ground truth");
  CLI::Option* dir =
      sub->add_option(
             "DIR", cmd.dir,
             "Middlebury (DIR/<seq>/frame10.png, frame11.png, flow10.flo), MPI-Sintel "
             "(flow/ with clean/ or final/) or KITTI (image_0/ or image_2/ with flow_occ/) "
             "tree; found by its layout")
          ->type_name("DIR");
  CLI::Option* pair =
      sub->add_option("--pair", cmd.pairs,
                      "an image pair and its ground truth (.flo, or KITTI 16-bit .png); repeatable")
          ->type_name("A B GT")
          ->type_size(3)
          ->allow_extra_args(false);
  sub->add_option("--exclude-mask", cmd.exclude_masks,
                  "pixels not scored (non-zero) for each --pair, in the same order")
      ->type_name("IMAGE")
      ->needs(pair);
  dir->excludes(pair);
  sub->add_option("--layout", cmd.layout, "layout of DIR (auto: found from its folders)")
      ->type_name("LAYOUT")
      ->check(CLI::IsMember({"auto", "middlebury", "sintel", "kitti"}))
      ->capture_default_str()
      ->needs(dir);
  sub->add_option("--pass", cmd.find.pass,
                  "Sintel rendering pass (auto: per scene, the first of clean, final, albedo "
                  "that the tree has; the pass shows in each row's name)")
      ->type_name("PASS")
      ->check(CLI::IsMember({"auto", "clean", "final", "albedo"}))
      ->capture_default_str()
      ->needs(dir);
  sub->add_option("--scene", cmd.find.scene,
                  "only this scene of DIR (Sintel alley_1, Middlebury Venus, KITTI 000042)")
      ->type_name("NAME")
      ->needs(dir);
  sub->add_option("--max-pairs", cmd.find.max_pairs,
                  "at most N pairs of DIR, evenly spaced over the sorted list (0: all)")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber)
      ->needs(dir);
  sub->add_option("--format", cmd.format, "output format")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"table", "csv", "json"}))
      ->capture_default_str();
  sub->add_option("-o,--output", cmd.output, "write the results to FILE instead of stdout")
      ->type_name("FILE");
  sub->add_option("--report", cmd.report,
                  "also write a self-contained HTML report (frames, colour-coded flows, error "
                  "maps, metrics per pair)")
      ->type_name("HTML");
  add_lk_options(*sub, cmd.lk);
  sub->callback([] { run_eval(cmd); });
}

}  // namespace roiflow::cli
