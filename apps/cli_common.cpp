#include "cli_common.hpp"

#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <type_traits>

#include "flow/large_motion.hpp"
#include "flow/pyramid.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {
namespace {

// The value an override takes: a member of LkParams, or a setter void(LkParams&, T).
template <class F>
struct ValueOf : ValueOf<decltype(std::function(std::declval<F>()))> {};
template <class T>
struct ValueOf<std::function<void(flow::LkParams&, T)>> {
  using type = T;
};
template <class T>
struct ValueOf<T flow::LkParams::*> {
  using type = T;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Shared Lucas-Kanade options

void add_lk_options(CLI::App& cmd, LkOptions& lk) {
  const std::string group = "Lucas-Kanade parameters (default: the preset's)";
  cmd.add_option("--preset", lk.preset, "parameter set the options below override")
      ->type_name("NAME")
      ->check(CLI::IsMember(flow::LkParams::preset_names()))
      ->capture_default_str()
      ->group(group);
  // Each override is kept as the change it makes, applied over the preset by lk_params().
  using P = flow::LkParams;
  const auto add = [&](const char* name, const std::string& help, auto set) {
    using T = typename ValueOf<decltype(set)>::type;
    const auto keep = [&lk, set](const T& v) {
      lk.overrides.push_back([set, v](P& p) {
        if constexpr (std::is_member_object_pointer_v<decltype(set)>) {
          p.*set = v;
        } else {
          set(p, v);
        }
      });
    };
    return cmd.add_option_function<T>(name, keep, help)->group(group);
  };
  add("--patch", "window side in pixels", &P::patch)->check(CLI::Range(3, 31));
  add("--levels", "pyramid levels, or auto (from the frame size and --expected-motion)",
      [](P& p, std::string v) { p.levels = v == "auto" ? 0 : std::stoi(v); })
      ->type_name("N|auto")
      ->check(CLI::Range(1, flow::kMaxLevels) | CLI::IsMember({"auto"}));
  add("--expected-motion",
      "largest motion to expect, pixels (0 = a quarter of the larger side): sets --levels auto "
      "and the coarse search's radius",
      &P::expected_motion)
      ->check(CLI::Range(0.0, 1e5));
  add("--search-radius",
      "coarse search at the coarsest level: largest radius in its pixels (0 = off)",
      &P::search_radius)
      ->check(CLI::Range(0, flow::kMaxSearchRadius));
  add("--coarsest-side", "--levels auto: the coarsest level's shorter side, pixels",
      &P::coarsest_side)
      ->check(CLI::Range(flow::kMinLevelSide, 480));
  add("--fuse-far-step",
      "candidate fusion before each level, first pass: neighbours this many pixels away (0 = off)",
      &P::fuse_far_step)
      ->check(CLI::Range(0, 32));
  add("--fuse-far-finest-level", "finest pyramid level the first fusion pass runs on",
      &P::fuse_far_finest_level)
      ->check(CLI::Range(0, flow::kMaxLevels - 1));
  add("--fuse-step", "candidate fusion, second pass: neighbours this many pixels away (0 = off)",
      &P::fuse_step)
      ->check(CLI::Range(0, 32));
  add("--fuse-finest-level", "finest pyramid level the second fusion pass runs on",
      &P::fuse_finest_level)
      ->check(CLI::Range(0, flow::kMaxLevels - 1));
  add("--mask-outside", "samples of frame t+1 outside the frame carry no brightness term (0 or 1)",
      [](P& p, int v) { p.mask_outside = v != 0; })
      ->check(CLI::IsMember({0, 1}));
  add("--finest-level", "pyramid level LK stops at; finer levels get the upsampled flow",
      &P::finest_level)
      ->check(CLI::Range(0, flow::kMaxLevels - 1));
  add("--iterations", "refinement iterations per level", &P::iterations)->check(CLI::Range(1, 50));
  add("--sigma", "pretreatment Gaussian sigma in pixels, 0..20 (0 = off)", &P::sigma);
  add("--lambda", "Tikhonov weight, (0, 1]", &P::lambda);
  add("--derivative", "image derivatives",
      [](P& p, std::string v) { p.derivative = flow::derivative_from_string(v); })
      ->type_name("NAME")
      ->check(CLI::IsMember({"hs", "scharr", "central"}));
  add("--robust-scale", "Cauchy reweighting scale of the residuals, 0..1 (0 = plain least squares)",
      &P::robust_scale);
  add("--level-median", "median filter of the flow after each coarse level (0 = off)",
      &P::level_median)
      ->check(CLI::IsMember({0, 3, 5}));
  add("--final-median", "median filter of the final flow (0 = off)", &P::final_median)
      ->check(CLI::IsMember({0, 3, 5}));
  cmd.add_option("--threads", lk.threads, "worker threads")
      ->check(CLI::Range(1, pipeline::kMaxThreads))
      ->capture_default_str()
      ->group(group);
}

flow::LkParams lk_params(const LkOptions& lk) {
  flow::LkParams params = flow::LkParams::preset(lk.preset);
  for (const auto& override_value : lk.overrides)
    override_value(params);
  try {
    params.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  return params;
}

void add_run_outputs(CLI::App& sub, std::string& video, std::string& summary, bool& progress,
                     const std::string& video_help) {
  progress = true;
  sub.add_option("--out", video, video_help)->type_name("VIDEO|DIR");
  sub.add_option("--summary", summary, "run summary (frames, fps per stage, ...) as JSON")
      ->type_name("JSON");
  sub.add_flag("!--no-progress", progress, "no progress bar on the terminal");
}

void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight) {
  sub.add_option("--start", source.start, "index of the first frame to read")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--max-frames", source.max_frames, "stop after this many frames (0 = all)")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--in-flight", in_flight,
                 "frames decoded ahead and in the pipeline at most (0 = 2 x threads + 2)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--decode-threads", source.decode_threads,
                 "a video's FFmpeg decoder threads (0 = one up to 1280x720, where more cost more "
                 "than they give, else FFmpeg's choice)")
      ->check(CLI::Range(0, 64));
}

}  // namespace roiflow::cli
