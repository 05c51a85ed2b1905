// What the roiflow subcommands share: the Lucas-Kanade options (declared once, added to any
// subcommand), output checks, a video run's options and summary line. A new subcommand lives in
// apps/<name>_command.cpp: add_<name>_command declares its options, its callback calls a library
// function and prints the result; one declaration below and one line in main() register it.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "pipeline/run.hpp"
#include "pipeline/signals.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {

// The preset and the overrides given on the command line, applied on top of it in order.
struct LkOptions {
  std::string preset = "paper";
  std::vector<std::function<void(flow::LkParams&)>> overrides;
  int threads = 1;
};

// Adds --preset, the overrides and --threads (default `lk.threads`) to `cmd`.
void add_lk_options(CLI::App& cmd, LkOptions& lk);
// The preset with the overrides applied; out-of-range values throw UsageError.
flow::LkParams lk_params(const LkOptions& lk);

// --out (to `video`), --summary and --no-progress.
void add_run_outputs(CLI::App& sub, std::string& video, std::string& summary, bool& progress,
                     const std::string& video_help);
// --start, --max-frames, --in-flight, --decode-threads.
void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight);

// The subcommands; a video run's exit code goes to `exit_code`.
void add_flow_command(CLI::App& app, int& exit_code);
void add_eval_command(CLI::App& app, int& exit_code);
void add_score_command(CLI::App& app, int& exit_code);
void add_track_command(CLI::App& app, int& exit_code);
void add_dense_command(CLI::App& app, int& exit_code);
void add_demo_command(CLI::App& app, int& exit_code);
void add_sweep_command(CLI::App& app, int& exit_code);
void add_benchmark_command(CLI::App& app, int& exit_code);
void add_scaling_command(CLI::App& app, int& exit_code);
void add_batch_command(CLI::App& app, int& exit_code);
void add_motion_check_command(CLI::App& app, int& exit_code);  // roiflow motion-check

}  // namespace roiflow::cli
