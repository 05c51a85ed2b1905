#include "cli_common.hpp"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "flow/large_motion.hpp"
#include "flow/pyramid.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Shared Lucas-Kanade options

void add_lk_options(CLI::App& cmd, LkOptions& lk) {
  const std::string group = "Lucas-Kanade parameters (default: the preset's)";
  cmd.add_option("--preset", lk.preset, "parameter set the options below override")
      ->type_name("NAME")
      ->check(CLI::IsMember(flow::LkParams::preset_names()))
      ->capture_default_str()
      ->group(group);
  cmd.add_option("--patch", lk.patch, "window side in pixels")
      ->check(CLI::Range(3, 31))
      ->group(group);
  cmd.add_option("--levels", lk.levels,
                 "pyramid levels, or auto (from the frame size and --expected-motion)")
      ->type_name("N|auto")
      ->check(CLI::Range(1, flow::kMaxLevels) | CLI::IsMember({"auto"}))
      ->group(group);
  cmd.add_option("--expected-motion", lk.expected_motion,
                 "largest motion to expect, pixels (0 = a quarter of the larger side): sets "
                 "--levels auto and the coarse search's radius")
      ->check(CLI::Range(0.0, 1e5))
      ->group(group);
  cmd.add_option("--search-radius", lk.search_radius,
                 "coarse search at the coarsest level: largest radius in its pixels (0 = off)")
      ->check(CLI::Range(0, flow::kMaxSearchRadius))
      ->group(group);
  cmd.add_option("--coarsest-side", lk.coarsest_side,
                 "--levels auto: the coarsest level's shorter side, pixels")
      ->check(CLI::Range(flow::kMinLevelSide, 480))
      ->group(group);
  cmd.add_option("--fuse-far-step", lk.fuse_far_step,
                 "candidate fusion before each level, first pass: neighbours this many pixels "
                 "away (0 = off)")
      ->check(CLI::Range(0, 32))
      ->group(group);
  cmd.add_option("--fuse-far-finest-level", lk.fuse_far_finest_level,
                 "finest pyramid level the first fusion pass runs on")
      ->check(CLI::Range(0, flow::kMaxLevels - 1))
      ->group(group);
  cmd.add_option("--fuse-step", lk.fuse_step,
                 "candidate fusion, second pass: neighbours this many pixels away (0 = off)")
      ->check(CLI::Range(0, 32))
      ->group(group);
  cmd.add_option("--fuse-finest-level", lk.fuse_finest_level,
                 "finest pyramid level the second fusion pass runs on")
      ->check(CLI::Range(0, flow::kMaxLevels - 1))
      ->group(group);
  cmd.add_option("--mask-outside", lk.mask_outside,
                 "samples of frame t+1 outside the frame carry no brightness term (0 or 1)")
      ->check(CLI::IsMember({0, 1}))
      ->group(group);
  cmd.add_option("--finest-level", lk.finest_level,
                 "pyramid level LK stops at; finer levels get the upsampled flow")
      ->check(CLI::Range(0, flow::kMaxLevels - 1))
      ->group(group);
  cmd.add_option("--iterations", lk.iterations, "refinement iterations per level")
      ->check(CLI::Range(1, 50))
      ->group(group);
  cmd.add_option("--sigma", lk.sigma, "pretreatment Gaussian sigma in pixels, 0..20 (0 = off)")
      ->group(group);
  cmd.add_option("--lambda", lk.lambda, "Tikhonov weight, (0, 1]")->group(group);
  cmd.add_option("--derivative", lk.derivative, "image derivatives")
      ->type_name("NAME")
      ->check(CLI::IsMember({"hs", "scharr", "central"}))
      ->group(group);
  cmd.add_option("--robust-scale", lk.robust_scale,
                 "Cauchy reweighting scale of the residuals, 0..1 (0 = plain least squares)")
      ->group(group);
  cmd.add_option("--level-median", lk.level_median,
                 "median filter of the flow after each coarse level (0 = off)")
      ->check(CLI::IsMember({0, 3, 5}))
      ->group(group);
  cmd.add_option("--final-median", lk.final_median, "median filter of the final flow (0 = off)")
      ->check(CLI::IsMember({0, 3, 5}))
      ->group(group);
  cmd.add_option("--threads", lk.threads, "worker threads")
      ->check(CLI::Range(1, pipeline::kMaxThreads))
      ->capture_default_str()
      ->group(group);
}

flow::LkParams lk_params(const LkOptions& lk) {
  flow::LkParams params = flow::LkParams::preset(lk.preset);
  if (lk.patch) params.patch = *lk.patch;
  if (lk.levels) params.levels = *lk.levels == "auto" ? 0 : std::stoi(*lk.levels);
  if (lk.expected_motion) params.expected_motion = *lk.expected_motion;
  if (lk.search_radius) params.search_radius = *lk.search_radius;
  if (lk.coarsest_side) params.coarsest_side = *lk.coarsest_side;
  if (lk.fuse_far_step) params.fuse_far_step = *lk.fuse_far_step;
  if (lk.fuse_far_finest_level) params.fuse_far_finest_level = *lk.fuse_far_finest_level;
  if (lk.fuse_step) params.fuse_step = *lk.fuse_step;
  if (lk.fuse_finest_level) params.fuse_finest_level = *lk.fuse_finest_level;
  if (lk.mask_outside) params.mask_outside = *lk.mask_outside != 0;
  if (lk.finest_level) params.finest_level = *lk.finest_level;
  if (lk.iterations) params.iterations = *lk.iterations;
  if (lk.sigma) params.sigma = *lk.sigma;
  if (lk.lambda) params.lambda = *lk.lambda;
  if (lk.derivative) params.derivative = flow::derivative_from_string(*lk.derivative);
  if (lk.robust_scale) params.robust_scale = *lk.robust_scale;
  if (lk.level_median) params.level_median = *lk.level_median;
  if (lk.final_median) params.final_median = *lk.final_median;
  try {
    params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  return params;
}

// ---------------------------------------------------------------------------------------------
// Output helpers

int default_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

std::string errors_line(const flow::FlowErrors& e) {
  return "AAE " + fixed(e.aae_deg, 3) + " deg, EPE " + fixed(e.epe, 4) + " px, R1 " +
         fixed(e.r1, 2) + " %, R3 " + fixed(e.r3, 2) + " %";
}

void check_output_path(const std::string& path, const std::string& option) {
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error(option + ": directory '" + parent.string() + "' of '" + path + "' does not exist");
  }
  if (fs::is_directory(path, ec)) throw Error(option + ": '" + path + "' is a directory");
}

void check_image_output(const std::string& path, const std::string& option) {
  check_output_path(path, option);
  if (!cv::haveImageWriter(path)) {
    throw UsageError(option + ": cannot write an image named '" + path +
                     "' (use an extension such as .png)");
  }
}

}  // namespace roiflow::cli
