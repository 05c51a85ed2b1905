#include "pipeline/eval_runs.hpp"

#include <chrono>
#include <filesystem>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/flo_io.hpp"
#include "eval/image_io.hpp"
#include "flow/color_code.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/sweep_plot.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;

}  // namespace

FlowRun run_flow(const eval::FlowInput& in, const flow::LkParams& params, int threads) {
  const TbbExecutor executor;
  FlowRun r;
  const auto start = std::chrono::steady_clock::now();
  r.flow = run_with_threads(threads, [&] {
    return flow::dense_flow(in.frame0, in.frame1, params, flow::FlowOptions{}, &executor).flow;
  });
  r.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!in.truth.empty()) r.errors = flow::flow_errors(r.flow, in.truth);
  return r;
}

void FlowFiles::check() const {
  check_output_path(flo, "-o");
  if (!color.empty()) eval::check_image_output(color, "--color");
  if (!legend.empty()) eval::check_image_output(legend, "--legend");
}

std::vector<std::string> write_flow_files(const FlowFiles& files, const eval::FlowInput& in,
                                          const FlowRun& run) {
  if (run.errors && run.errors->pixels == 0) {
    throw Error("--gt: the ground truth is unknown at every pixel");
  }
  std::vector<std::string> written{files.flo};
  eval::write_flo(files.flo, run.flow);
  if (!files.color.empty()) {
    // Against a ground truth, the truth's largest vector saturates, so the two pictures compare.
    const float scale = in.truth.empty() ? -1.f : flow::max_magnitude(in.truth);
    eval::write_image_atomically(written.emplace_back(files.color),
                                 flow::flow_to_color(run.flow, scale));
  }
  if (!files.legend.empty()) {
    eval::write_image_atomically(written.emplace_back(files.legend), flow::color_wheel_legend());
  }
  return written;
}

std::string flow_text(const eval::FlowInput& in, const FlowRun& run,
                      const std::vector<std::string>& written) {
  std::string text = "flow " + size_text(in.frame0.size()) + " (" + in.source +
                     "): " + fixed(run.ms, 2) + " ms, wrote " + joined(written) + "\n";
  if (run.errors) text += "error vs ground truth: " + eval::errors_text(*run.errors) + "\n";
  return text;
}

std::vector<eval::EvalRow> run_eval(const std::vector<eval::EvalPair>& pairs,
                                    const flow::LkParams& params, int threads,
                                    report::HtmlReport* report) {
  const TbbExecutor executor;
  std::vector<eval::EvalRow> rows;
  run_with_threads(threads, [&] {
    for (const eval::EvalPair& pair : pairs) {
      eval::EvalImages images;
      rows.push_back(eval::evaluate_pair(pair, params, &executor, report ? &images : nullptr));
      if (report) report->add(rows.back(), images);
    }
  });
  return rows;
}

void EvalOutputs::check() const {
  if (!output.empty()) check_output_path(output, "-o");
  if (!report.empty()) check_output_path(report, "--report");
}

std::string run_eval(const std::vector<eval::EvalPair>& pairs, const flow::LkParams& params,
                     const std::string& preset, int threads, const EvalOutputs& outputs) {
  std::optional<report::HtmlReport> html;
  if (!outputs.report.empty()) html.emplace(outputs.title, preset, params);
  const std::vector<eval::EvalRow> rows = run_eval(pairs, params, threads, html ? &*html : nullptr);
  const std::string text = outputs.format == "csv"    ? eval::format_csv(rows)
                           : outputs.format == "json" ? eval::format_json(rows, preset, params)
                                                      : eval::format_table(rows);
  if (html) html->write(outputs.report);
  std::string said = outputs.output.empty() ? text : "";
  if (!outputs.output.empty()) {
    write_text_atomically(outputs.output, text);
    said = "evaluated " + std::to_string(rows.size()) + " pairs, wrote " + outputs.output + "\n";
  }
  if (html) said += "wrote report " + outputs.report + "\n";
  return said;
}

SweepRunResult run_sweep(const SweepRunOptions& o) {
  make_output_dir(o.out_dir, "--out");
  const std::string csv_path = (fs::path(o.out_dir) / "sweep.csv").string();
  const TbbExecutor executor;
  SweepRunResult r;
  r.written.push_back(csv_path);
  run_with_threads(o.threads, [&] {
    for (const auto& [p, values] : o.plan) {
      const std::size_t n = values.size();
      const auto progress = [&](const eval::SweepRow& row, std::size_t i) {
        if (o.progress) o.progress(row, i, n);
      };
      const std::vector<eval::SweepRow> part =
          eval::sweep(o.pairs, o.base, p, values, &executor, progress, o.repeats);
      r.rows.insert(r.rows.end(), part.begin(), part.end());
      write_text_atomically(csv_path, eval::sweep_csv(r.rows));
      const std::string svg =
          (fs::path(o.out_dir) / (std::string(eval::to_string(p)) + ".svg")).string();
      report::write_plot_svg(svg, report::sweep_plot(p, r.rows, o.subtitle));
      r.written.push_back(svg);
    }
  });
  return r;
}

std::string sweep_text(const SweepRunResult& r, const SweepRunOptions& o) {
  return eval::sweep_table(r.rows) + "swept " + std::to_string(r.rows.size()) + " values over " +
         std::to_string(o.pairs.size()) + " pairs, " + std::to_string(o.threads) +
         " threads, time per pair the fastest of " + std::to_string(o.repeats) +
         (o.repeats == 1 ? " run" : " runs") + "; wrote " + joined(r.written) + "\n";
}

}  // namespace roiflow::pipeline
