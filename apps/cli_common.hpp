// Pieces the roiflow subcommands share: the usage error, the Lucas-Kanade options, output
// checks and atomic writes, number formatting.
#pragma once

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"

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

void add_lk_options(CLI::App& cmd, LkOptions& lk);
// The preset with the overrides applied; out-of-range values throw UsageError.
flow::LkParams lk_params(const LkOptions& lk);

std::string size_string(cv::Size size);
std::string fixed(double value, int decimals);
std::string errors_line(const flow::FlowErrors& e);

// Catches a mistyped output path before minutes of computation are spent.
void check_output_path(const std::string& path, const std::string& option);
void check_image_output(const std::string& path, const std::string& option);

// roiflow track, dense and demo (video_commands.cpp); a run's exit code goes to `exit_code`.
void add_video_commands(CLI::App& app, int& exit_code);
void add_sweep_command(CLI::App& app);      // roiflow sweep (sweep_command.cpp)
void add_benchmark_command(CLI::App& app);  // roiflow benchmark (benchmark_command.cpp)
void add_scaling_command(CLI::App& app);    // roiflow scaling (scaling_command.cpp)
// roiflow demo --objects N (mot_demo_command.cpp); returns the exit code.
int run_objects_demo(const std::string& dir, int objects, int frames, int threads, bool progress);
// roiflow score --mot PRED GT (mot_score_command.cpp)
void print_mot_score(const std::string& pred, const std::string& gt, const std::string& format);

}  // namespace roiflow::cli
