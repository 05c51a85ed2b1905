#include "cli_common.hpp"

#include <iostream>
#include <limits>

#include "flow/lk_options.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::cli {

void add_lk_options(CLI::App& cmd, LkOptions& lk) {
  const std::string group = "Lucas-Kanade parameters (default: the preset's)";
  cmd.add_option("--preset", lk.preset, "parameter set the options below override")
      ->type_name("NAME")
      ->check(CLI::IsMember(flow::LkParams::preset_names()))
      ->capture_default_str()
      ->group(group);
  // Each override is kept as the change it makes, applied over the preset by lk_params().
  using T = flow::LkOption::Type;
  for (const flow::LkOption& o : flow::lk_options()) {
    const auto keep = [&lk, &o](double v, const std::string& w) {
      lk.overrides.push_back([&o, v, w](flow::LkParams& p) { o.set(p, v, w); });
    };
    const std::string name = std::string("--") + o.name;
    CLI::Option* opt =
        o.type == T::Int ? cmd.add_option_function<int>(name, [keep](int v) { keep(v, ""); })
        : o.type == T::Real
            ? cmd.add_option_function<double>(name, [keep](double v) { keep(v, ""); })
            : cmd.add_option_function<std::string>(name,
                                                   [keep](const std::string& w) { keep(0, w); });
    opt->description(o.help)->group(group);
    if (o.type_name != nullptr) opt->type_name(o.type_name);
    const bool range = o.min < o.max;
    const CLI::Range int_range(static_cast<int>(o.min), static_cast<int>(o.max));
    if (o.type == T::Int && range) opt->check(int_range);
    if (o.type == T::Real && range) opt->check(CLI::Range(o.min, o.max));
    if (!o.int_choices.empty()) {
      opt->check(CLI::IsMember(std::vector<int>(o.int_choices.begin(), o.int_choices.end())));
    }
    if (!o.choices.empty()) {
      opt->check(range ? int_range | CLI::IsMember(o.choices) : CLI::IsMember(o.choices));
    }
  }
  cmd.add_option("--threads", lk.threads, "worker threads")
      ->check(CLI::Range(1, pipeline::kMaxThreads))
      ->capture_default_str()
      ->group(group);
}

flow::LkParams lk_params(const LkOptions& lk) {
  flow::LkParams params = flow::LkParams::preset(lk.preset);
  for (const auto& override_value : lk.overrides)
    override_value(params);
  as_usage([&] { params.validate(); });
  return params;
}

int run_end(const pipeline::Ending& end) {
  if (end.exit_code != 0) std::cerr << "roiflow: error: " << end.message << "\n";
  return end.exit_code;
}

void add_run_outputs(CLI::App& sub, std::string& video, std::string& summary, bool& progress,
                     const std::string& video_help) {
  progress = true;
  sub.add_option("--out", video, video_help)->type_name("VIDEO|DIR");
  sub.add_option("--summary", summary, "run summary (frames, fps per stage, ...), JSON");
  sub.add_flag("!--no-progress", progress, "no progress bar on the terminal");
}

std::pair<CLI::Option*, CLI::Option*> add_pair_inputs(CLI::App& sub, std::string& dir,
                                                      std::vector<std::vector<std::string>>& pairs,
                                                      const std::string& dir_help) {
  CLI::Option* d = sub.add_option("DIR", dir, dir_help)->type_name("DIR");
  CLI::Option* p = sub.add_option("--pair", pairs, "an image pair and its ground truth; repeatable")
                       ->type_name("A B GT")
                       ->type_size(3)
                       ->allow_extra_args(false);
  d->excludes(p);
  return {d, p};
}

void add_tracker_options(CLI::App& sub, tracking::TrackerParams& tracker, std::string* mode,
                         const std::string& who) {
  sub.add_option("--roi", tracker.roi, who + "side of the local region in pixels")
      ->check(CLI::Range(8, 4096))
      ->capture_default_str();
  sub.add_option("--lk-patches", tracker.local.lk_patches,
                 who + "LK on the coarsest level where the object spans this many LK patches")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  if (mode == nullptr) return;
  sub.add_option("--mode", *mode, "local: LK in a local region; global: in the whole frame")
      ->check(CLI::IsMember({"local", "global"}))
      ->capture_default_str();
}

void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight) {
  sub.add_option("--start", source.start, "index of the first frame to read")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--max-frames", source.max_frames, "stop after this many frames (0 = all)")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--in-flight", in_flight, "frames in the pipeline at most (0 = 2 x threads + 2)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--decode-threads", source.decode_threads,
                 "FFmpeg decoder threads (0 = one up to 1280x720, else FFmpeg's choice)")
      ->check(CLI::Range(0, 64));
}

}  // namespace roiflow::cli
