// What the subcommands share: the LK options (declared once), groups of options, usage checks.
// A new subcommand lives in apps/<name>_command.cpp: add_<name>_command declares its options,
// its callback calls a library function and prints; a declaration below and main() register it.
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

struct LkOptions {  // the preset, then the overrides given, in order
  std::string preset = "paper";
  std::vector<std::function<void(flow::LkParams&)>> overrides;
  int threads = 1;
};

// Adds --preset, the overrides and --threads (default `lk.threads`) to `cmd`.
void add_lk_options(CLI::App& cmd, LkOptions& lk);
// The preset with the overrides applied; out-of-range values throw UsageError.
flow::LkParams lk_params(const LkOptions& lk);

// Runs `check` (a validate(), a parse): its roiflow::Error becomes a UsageError (exit code 2),
// its message after `prefix`.
template <class Check>
void as_usage(Check&& check, const std::string& prefix = "") {
  try {
    check();
  } catch (const Error& e) {
    throw UsageError(prefix + e.what());
  }
}

// A run's ending: an error line on stderr unless it completed; returns the exit code.
int run_end(const pipeline::Ending& end);

// --out (to `video`), --summary and --no-progress.
void add_run_outputs(CLI::App& sub, std::string& video, std::string& summary, bool& progress,
                     const std::string& video_help);
// DIR and --pair A B GT (repeatable), which exclude each other; returns the two options.
std::pair<CLI::Option*, CLI::Option*> add_pair_inputs(CLI::App& sub, std::string& dir,
                                                      std::vector<std::vector<std::string>>& pairs,
                                                      const std::string& dir_help);
// --roi and --lk-patches (prefixed "roiflow: " in `who`), and --mode when `mode` is given.
void add_tracker_options(CLI::App& sub, tracking::TrackerParams& tracker,
                         std::string* mode = nullptr, const std::string& who = "");
// --start, --max-frames, --in-flight, --decode-threads.
void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight);

// The subcommands; a run's exit code goes to `exit_code`.
using AddCommand = void(CLI::App& app, int& exit_code);
AddCommand add_flow_command, add_eval_command, add_score_command, add_track_command,
    add_dense_command, add_demo_command, add_sweep_command, add_benchmark_command,
    add_scaling_command, add_batch_command, add_motion_check_command;

}  // namespace roiflow::cli
