// roiflow scaling: the same run at several thread counts; throughput, speedup and efficiency
// (pipeline::run_scaling, src/pipeline/scaling.hpp).
//
//   roiflow scaling synthetic:300:640x480:16 --threads 1,2 --mode local --out out/scaling
//   -> out/scaling/scaling.csv (threads,fps,tracker_fps,speedup,efficiency), scaling.svg
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "pipeline/scaling.hpp"
#include "report/plot.hpp"

namespace roiflow::cli {
namespace {

namespace fs = std::filesystem;

struct ScalingCommand {
  LkOptions lk;
  std::string input;
  std::vector<int> threads;
  std::string mode = "local";
  std::string out;
  long long max_frames = 0;
  int repeats = 1;
};

// The output folder is created when missing; its parent must exist.
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

void run_scaling_command(const ScalingCommand& cmd) {
  pipeline::ScalingOptions o;
  o.input = cmd.input;
  o.threads = cmd.threads;
  o.mode = pipeline::scaling_mode_from_string(cmd.mode);
  o.lk = lk_params(cmd.lk);
  o.max_frames = cmd.max_frames;
  o.repeats = cmd.repeats;
  try {
    o.validate();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  prepare_out_dir(cmd.out);
  const pipeline::ScalingResult r = pipeline::run_scaling(o);
  const std::string csv = (fs::path(cmd.out) / "scaling.csv").string();
  const std::string svg = (fs::path(cmd.out) / "scaling.svg").string();
  write_text_atomically(csv, pipeline::scaling_csv(r));
  report::write_plot_svg(svg, pipeline::scaling_plot(r));
  std::cout << "scaling " << pipeline::to_string(r.mode) << " mode, " << r.input << "\n"
            << "threads      fps  tracker_fps  speedup  efficiency\n";
  for (const pipeline::ScalingRow& row : r.rows) {
    std::printf("%7d %8.1f %12.1f %8.2f %11.2f\n", row.threads, row.fps, row.tracker_fps,
                row.speedup, row.efficiency);
  }
  std::cout << std::flush << "wrote " << csv << ", " << svg << "\n";
}

}  // namespace

void add_scaling_command(CLI::App& app) {
  static ScalingCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "scaling", "The same run at several thread counts: fps, speedup, efficiency; CSV and SVG");
  sub->add_option("INPUT", cmd.input,
                  "video file, image-sequence folder, or synthetic:N[:WxH][:OBJECTS]")
      ->required();
  // The LK options' own --threads (one count) gives way to the list.
  add_lk_options(*sub, cmd.lk);
  sub->remove_option(sub->get_option("--threads"));
  sub->add_option("--threads", cmd.threads, "comma-separated thread counts, e.g. 1,2,4")
      ->type_name("LIST")
      ->delimiter(',')
      ->expected(1, 64)
      ->required();
  sub->add_option("--mode", cmd.mode,
                  "local: tracking with the local treatment; global: the global treatment every "
                  "frame; dense: dense flow of every frame pair")
      ->check(CLI::IsMember({"local", "global", "dense"}))
      ->capture_default_str();
  sub->add_option("--out", cmd.out, "folder for scaling.csv and scaling.svg (created if missing)")
      ->type_name("DIR")
      ->required();
  sub->add_option("--max-frames", cmd.max_frames, "frames of the input to use (0 = all)")
      ->check(CLI::Range(0LL, 1'000'000'000LL));
  sub->add_option("--repeat", cmd.repeats,
                  "runs per thread count; the fastest is kept (noise of a shared machine)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->callback([] { run_scaling_command(cmd); });
}

}  // namespace roiflow::cli
