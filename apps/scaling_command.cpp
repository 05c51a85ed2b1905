// roiflow scaling: one run at several thread counts; fps, speedup, efficiency (pipeline/scaling).
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/scaling.hpp"

namespace roiflow::cli {

void add_scaling_command(CLI::App& app, int& /*exit_code*/) {
  static LkOptions lk;
  static pipeline::ScalingOptions run;  // INPUT, --threads, --max-frames, --repeat
  static std::string mode = "local", out;
  CLI::App* sub = app.add_subcommand(
      "scaling", "The same run at several thread counts: fps, speedup, efficiency; CSV and SVG");
  sub->add_option("INPUT", run.input, "video file, image folder, or synthetic:N[:WxH][:OBJECTS]")
      ->required();
  add_lk_options(*sub, lk);  // its --threads (one count) gives way to the list
  sub->remove_option(sub->get_option("--threads"));
  sub->add_option("--threads", run.threads, "comma-separated thread counts, e.g. 1,2,4")
      ->type_name("LIST")
      ->delimiter(',')
      ->expected(1, 64)
      ->required();
  sub->add_option("--mode", mode,
                  "local or global: tracking with that treatment; dense: every frame pair's flow")
      ->check(CLI::IsMember({"local", "global", "dense"}))
      ->capture_default_str();
  sub->add_option("--out", out, "folder for scaling.csv and scaling.svg")->required();
  sub->add_option("--max-frames", run.max_frames, "frames of the input to use (0 = all)")
      ->check(CLI::Range(0LL, 1'000'000'000LL));
  sub->add_option("--repeat", run.repeats, "runs per thread count, the fastest kept")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->callback([] {
    pipeline::ScalingOptions o = run;
    o.mode = pipeline::scaling_mode_from_string(mode);
    o.lk = lk_params(lk);
    as_usage([&] { o.validate(); });
    make_output_dir(out, "--out");
    const pipeline::ScalingResult r = pipeline::run_scaling(o);
    const std::vector<std::string> written = pipeline::write_scaling(r, out);
    std::cout << pipeline::scaling_text(r) << "wrote " << joined(written) << "\n";
  });
}

}  // namespace roiflow::cli
