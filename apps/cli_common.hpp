// Pieces the roiflow subcommands share: the usage error, the Lucas-Kanade options (declared
// once, added to any subcommand), output checks, the options and the ending of a video run.
//
// A new subcommand lives in apps/<name>_command.cpp: it defines add_<name>_command below (CLI11
// options into a struct, a callback that calls a library function and prints its result) and
// gets one line in main() (roiflow.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "pipeline/run.hpp"

namespace roiflow::cli {

// A command line that CLI11 accepts but that makes no sense (conflicting inputs, LK
// parameters out of range): reported like CLI11's own parse errors, with exit code 2.
class UsageError : public Error {
 public:
  using Error::Error;
};

// Overrides stay empty unless given, so they apply on top of whichever preset was chosen.
struct LkOptions {
  std::string preset = "paper";
  std::optional<int> patch, iterations, level_median, final_median;
  std::optional<std::string> levels;  // N or "auto"
  std::optional<int> coarsest_side, search_radius, fuse_far_step, fuse_far_finest_level;
  std::optional<int> fuse_step, fuse_finest_level, mask_outside, finest_level;
  std::optional<double> expected_motion;
  std::optional<double> sigma, lambda, robust_scale;
  std::optional<std::string> derivative;
  int threads = 1;
};

// Adds --preset, the overrides and --threads (default `lk.threads`) to `cmd`.
void add_lk_options(CLI::App& cmd, LkOptions& lk);
// The preset with the overrides applied; out-of-range values throw UsageError.
flow::LkParams lk_params(const LkOptions& lk);
int default_threads();  // the hardware's, within 1..kMaxThreads

std::string errors_line(const flow::FlowErrors& e);

// Catches a mistyped output path before minutes of computation are spent.
void check_output_path(const std::string& path, const std::string& option);
void check_image_output(const std::string& path, const std::string& option);

// ------------------------------------------------------------------------- video runs (run_cli)

// The output options every video subcommand shares.
struct RunOutputs {
  std::string video;    // --out
  std::string summary;  // --summary
  bool progress = true;
};
void add_run_outputs(CLI::App& sub, RunOutputs& out, const std::string& video_help);
// --start, --max-frames, --in-flight, --decode-threads.
void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight);

// While alive, SIGINT and SIGTERM set cancel_flag(): a run stops reading, finishes the frames in
// flight, closes its outputs, and the command exits with 128 + the signal.
class SignalScope {
 public:
  SignalScope();
  ~SignalScope();
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

 private:
  void (*previous_int_)(int);
  void (*previous_term_)(int);
};
const std::atomic<bool>* cancel_flag();
int caught_signal();  // 0 when none

// Why a run that a signal or a broken input cut short ended; exit_code 0 when it did not.
struct Ending {
  int exit_code = 0;
  std::string message;
};
Ending ending(pipeline::RunEnd end, long long frames, const std::string& status);

// "track <input>: N frames in ..." and its second line; then "  wrote a, b" unless empty.
void print_track_summary(const std::string& what, const pipeline::TrackSummary& s,
                         const std::vector<std::string>& written);
std::string joined(const std::vector<std::string>& items);  // "a, b, c"

// ----------------------------------------------------------------------------- the subcommands
// Each registers itself on `app`; a video run's exit code goes to `exit_code`.
void add_flow_command(CLI::App& app, int& exit_code);
void add_eval_command(CLI::App& app, int& exit_code);
void add_score_command(CLI::App& app, int& exit_code);
void add_track_command(CLI::App& app, int& exit_code);
void add_dense_command(CLI::App& app, int& exit_code);
void add_demo_command(CLI::App& app, int& exit_code);
void add_sweep_command(CLI::App& app, int& exit_code);

}  // namespace roiflow::cli
