#include "pipeline/eval_runs.hpp"

#include <chrono>
#include <filesystem>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
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

}  // namespace roiflow::pipeline
