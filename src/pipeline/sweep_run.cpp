#include "pipeline/sweep_run.hpp"

#include <filesystem>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/sweep_plot.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;

void prepare_out_dir(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  if (fs::exists(dir, ec)) throw Error("--out: '" + dir + "' exists and is not a directory");
  const fs::path parent = fs::path(dir).lexically_normal().parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error("--out: directory '" + parent.string() + "' of '" + dir + "' does not exist");
  }
  if (!fs::create_directory(dir, ec) && !fs::is_directory(dir)) {
    throw Error("--out: cannot create directory '" + dir + "': " + ec.message());
  }
}

}  // namespace

SweepRunResult run_sweep(const SweepRunOptions& o) {
  prepare_out_dir(o.out_dir);
  const std::string csv_path = (fs::path(o.out_dir) / "sweep.csv").string();
  const TbbExecutor executor;
  SweepRunResult r;
  r.written.push_back(csv_path);
  run_with_threads(o.threads, [&] {
    for (std::size_t k = 0; k < o.params.size(); ++k) {
      const eval::SweepParam p = o.params[k];
      const std::size_t n = o.values[k].size();
      const auto progress = [&](const eval::SweepRow& row, std::size_t i) {
        if (o.progress) o.progress(row, i, n);
      };
      const std::vector<eval::SweepRow> part =
          eval::sweep(o.pairs, o.base, p, o.values[k], &executor, progress, o.repeats);
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
