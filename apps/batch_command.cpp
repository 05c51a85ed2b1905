// roiflow batch videos/ --out out/batch -- track --roi 60: many videos, several at once.
#include <filesystem>
#include <iostream>

#include "cli_common.hpp"
#include "pipeline/batch.hpp"

namespace roiflow::cli {
namespace {

struct BatchCommand {
  std::string input;
  pipeline::BatchOptions run;  // --out, --threads, --parallel, --max-frames
  bool no_csv = false;
  std::vector<std::string> job;  // after "--": track|dense [options]
};

// The job's own command line, parsed like `roiflow track` / `roiflow dense` options.
pipeline::BatchOptions job_options(const BatchCommand& cmd) {
  if (cmd.job.empty()) throw UsageError("batch needs a job after '--': track or dense");
  const std::string& kind = cmd.job[0];
  if (kind != "track" && kind != "dense") {
    throw UsageError("batch: the job after '--' must be track or dense, got '" + kind + "'");
  }
  CLI::App app{"roiflow batch job", "roiflow batch -- " + kind};
  pipeline::BatchOptions o = cmd.run;
  o.job = kind == "track" ? pipeline::BatchJob::Track : pipeline::BatchJob::Dense;
  LkOptions lk;
  std::string mode = "local";
  add_lk_options(app, lk);
  if (o.job == pipeline::BatchJob::Track) {
    add_tracker_options(app, o.tracker, &mode);
  } else {
    app.add_option("--max-motion", o.max_motion, "flow magnitude at full colour saturation")
        ->check(CLI::Range(0.0, 1e6));
  }
  std::vector<std::string> args(cmd.job.rbegin(), cmd.job.rend() - 1);  // CLI11 wants them reversed
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw UsageError("batch -- " + kind + ": " + e.what());
  }
  if (app.count("--threads") > 0) {
    throw UsageError("batch: give --threads before '--' (the batch's own arena)");
  }
  o.lk = o.tracker.lk = lk_params(lk);
  o.tracker.mode = tracking::track_mode_from_string(mode);
  if (o.job == pipeline::BatchJob::Track) as_usage([&] { o.tracker.validate(); });
  return o;
}

}  // namespace

void add_batch_command(CLI::App& app, int& exit_code) {
  static BatchCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "batch",
      "track or dense over many videos, one output folder each, several at once; a killed "
      "batch resumes (docs/DROPIN.md)");
  sub->add_option("INPUT", cmd.input,
                  "folder of videos, list file (.txt/.lst, one path a line), or one video")
      ->required();
  sub->add_option("JOB", cmd.job, "after '--': track|dense and that job's options")
      ->type_name("-- track|dense [OPTIONS]");
  sub->add_option("--out", cmd.run.out_dir, "folder for one folder per video and batch.csv")
      ->required();
  sub->add_option("--threads", cmd.run.threads,
                  "threads of the one arena all videos share (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_option("--parallel", cmd.run.parallel, "videos at once (0 = the thread count)")
      ->check(CLI::Range(0, 4096));
  sub->add_option("--max-frames", cmd.run.max_frames, "frames per video at most (0 = all)")
      ->check(CLI::Range(0LL, 1000000000000LL));
  sub->add_flag("--no-csv", cmd.no_csv,
                "write no batch.csv (one task of a sharded batch: scripts/dask_batch.py)");
  sub->callback([&exit_code] {
    pipeline::BatchOptions o = job_options(cmd);
    o.cancel = pipeline::cancel_flag();
    if (!cmd.no_csv) o.csv = (std::filesystem::path(o.out_dir) / "batch.csv").string();
    o.on_row = [](const pipeline::BatchRow& row) {
      std::cout << pipeline::batch_row_line(row) << std::endl;
    };
    const std::vector<std::string> videos = pipeline::batch_inputs(cmd.input);
    pipeline::SignalScope signals;
    const std::vector<pipeline::BatchRow> rows = pipeline::run_batch(videos, o);
    std::cout << pipeline::batch_summary_line(rows, o.csv) << "\n";
    exit_code = run_end(pipeline::batch_ending(rows));
  });
}

}  // namespace roiflow::cli
