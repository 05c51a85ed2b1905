// roiflow batch: many videos, one output folder each, several at once (pipeline/batch.hpp).
//
//   roiflow batch videos/ --out out/batch -- track --roi 60
//   roiflow batch list.txt --out out/flow --threads 4 -- dense --preset fast
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cli_common.hpp"
#include "pipeline/batch.hpp"
#include "pipeline/tbb_executor.hpp"
#include "stages/tracker.hpp"

namespace roiflow::cli {
namespace {

std::atomic<bool> g_batch_cancel{false};
std::atomic<int> g_batch_signal{0};

extern "C" void on_batch_signal(int signal) {
  g_batch_signal.store(signal);
  g_batch_cancel.store(true);
}

struct BatchCommand {
  std::string input;
  std::string out;
  int threads = 0;
  int parallel = 0;
  long long max_frames = 0;
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
  LkOptions lk;
  int roi = 50;
  double lk_patches = stages::LocalTrackerParams{}.lk_patches;
  std::string mode = "local";
  double max_motion = 0;
  add_lk_options(app, lk);
  if (kind == "track") {
    app.add_option("--roi", roi, "side of the local region in pixels")->check(CLI::Range(8, 4096));
    app.add_option("--lk-patches", lk_patches, "see roiflow track --help")
        ->check(CLI::Range(0.0, 100.0));
    app.add_option("--mode", mode, "local or global")->check(CLI::IsMember({"local", "global"}));
  } else {
    app.add_option("--max-motion", max_motion, "flow magnitude at full colour saturation")
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
  pipeline::BatchOptions options;
  options.lk = lk_params(lk);
  if (kind == "track") {
    options.job = pipeline::BatchJob::Track;
    options.tracker.lk = options.lk;
    options.tracker.mode = stages::track_mode_from_string(mode);
    options.tracker.roi = roi;
    options.tracker.local.lk_patches = lk_patches;
    try {
      options.tracker.validate();
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
  } else {
    options.job = pipeline::BatchJob::Dense;
    options.max_motion = static_cast<float>(max_motion > 0 ? max_motion : -1.0);
  }
  return options;
}

int run_batch_command(const BatchCommand& cmd) {
  pipeline::BatchOptions options = job_options(cmd);
  options.out_dir = cmd.out;
  options.threads = cmd.threads;
  options.parallel = cmd.parallel;
  options.max_frames = cmd.max_frames;
  options.cancel = &g_batch_cancel;
  const std::vector<std::string> videos = pipeline::batch_inputs(cmd.input);
  pipeline::batch_names(videos);  // refuses two videos with one output folder, before any work
  const std::string csv = (std::filesystem::path(cmd.out) / "batch.csv").string();

  // batch.csv follows the videos as they end, in input order, so a killed batch leaves the rows
  // of what it finished.
  std::map<std::string, pipeline::BatchRow> ended;
  options.on_row = [&](const pipeline::BatchRow& row) {
    if (row.skipped) {
      std::cout << "skipped " << row.video << " (done earlier)\n";
    } else if (row.status == "done") {
      std::cout << "done    " << row.video << " (" << row.frames << " frames, " << fixed(row.fps, 1)
                << " fps) -> " << row.folder << "\n";
    } else {
      std::cout << row.status.substr(0, row.status.find(':')) << "  " << row.video
                << (row.status.find(':') != std::string::npos
                        ? ":" + row.status.substr(row.status.find(':') + 1)
                        : std::string())
                << "\n";
    }
    std::cout.flush();
    ended[row.video] = row;
    if (!cmd.no_csv) {
      std::vector<pipeline::BatchRow> rows;
      for (const std::string& v : videos) {
        const auto it = ended.find(v);
        if (it != ended.end()) rows.push_back(it->second);
      }
      pipeline::write_batch_csv(csv, rows);
    }
  };

  auto previous_int = std::signal(SIGINT, on_batch_signal);
  auto previous_term = std::signal(SIGTERM, on_batch_signal);
  std::vector<pipeline::BatchRow> rows;
  try {
    rows = pipeline::run_batch(videos, options);
  } catch (...) {
    std::signal(SIGINT, previous_int);
    std::signal(SIGTERM, previous_term);
    throw;
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (!cmd.no_csv) pipeline::write_batch_csv(csv, rows);

  long long ran = 0, skipped = 0, failed = 0, cancelled = 0;
  for (const pipeline::BatchRow& r : rows) {
    if (r.skipped) {
      ++skipped;
    } else if (r.status == "done") {
      ++ran;
    } else if (r.status == "cancelled") {
      ++cancelled;
    } else {
      ++failed;
    }
  }
  std::cout << "batch: " << rows.size() << " videos: " << ran << " run, " << skipped
            << " already done, " << failed << " failed"
            << (cancelled > 0 ? ", " + std::to_string(cancelled) + " cancelled" : std::string())
            << (cmd.no_csv ? std::string() : "; wrote " + csv) << "\n";
  if (g_batch_signal.load() != 0) {
    std::cerr << "roiflow: error: interrupted; finished videos are kept, run again to resume\n";
    return 128 + g_batch_signal.load();
  }
  if (failed > 0) {
    std::cerr << "roiflow: error: " << failed << " of " << rows.size()
              << " videos failed (see batch.csv); run again to retry them\n";
    return 1;
  }
  return 0;
}

}  // namespace

void add_batch_command(CLI::App& app, int& exit_code) {
  static BatchCommand cmd;
  CLI::App* sub = app.add_subcommand(
      "batch",
      "Run track or dense over many videos, one output folder each, several at once; "
      "finished videos are skipped, so a killed batch resumes (docs/DROPIN.md)");
  sub->add_option("INPUT", cmd.input,
                  "folder of videos, list file (.txt/.lst, one path a line), or one video")
      ->required();
  sub->add_option("JOB", cmd.job, "after '--': track|dense and that job's options")
      ->type_name("-- track|dense [OPTIONS]");
  sub->add_option("--out", cmd.out, "output folder: one folder per video and batch.csv")
      ->required()
      ->type_name("DIR");
  sub->add_option("--threads", cmd.threads, "threads of the one arena all videos share (0 = all)")
      ->check(CLI::Range(0, pipeline::kMaxThreads));
  sub->add_option("--parallel", cmd.parallel, "videos at once (0 = the thread count)")
      ->check(CLI::Range(0, 4096));
  sub->add_option("--max-frames", cmd.max_frames, "frames per video at most (0 = all)")
      ->check(CLI::Range(0LL, 1000000000000LL));
  sub->add_flag("--no-csv", cmd.no_csv,
                "write no batch.csv (one task of a sharded batch: scripts/dask_batch.py)");
  sub->callback([&exit_code] { exit_code = run_batch_command(cmd); });
}

}  // namespace roiflow::cli
