// Batch: many videos, each run to its own output folder, several at once on one oneTBB arena,
// idempotent (a finished video is skipped, a killed batch resumes, nothing is half-written).
//
//   using namespace roiflow;
//   pipeline::BatchOptions options;
//   options.out_dir = "out/batch";
//   options.job = pipeline::BatchJob::Track;        // or Dense
//   options.threads = 4;                            // one arena for every video
//   std::vector<std::string> videos = pipeline::batch_inputs("videos/");   // or a .txt list
//   std::vector<pipeline::BatchRow> rows = pipeline::run_batch(videos, options);
//   pipeline::write_batch_csv("out/batch/batch.csv", rows);
//
// Each video gets the folder <out_dir>/<stem> (the file name without its extension; two inputs
// with the same stem are refused), holding for `track` the track log track.csv (the rows
// `roiflow track --log` writes for the same input and tracker parameters, ms aside) and for
// `dense` the colour-coded flow video flow.avi, plus status.json (video, status, frames, fps,
// seconds). The folder is built under a hidden partial name, .<stem>.partial.<host>.<pid>, and
// renamed into place only when the video is done: a folder named <stem> is always complete.
// That makes runs idempotent and safe to repeat or run twice at once (a Dask retry, two
// machines on one shared folder): a video whose folder exists is skipped (its row comes from its
// status.json, status "done"); when two runs finish the same video, the first rename wins and
// the other's partial folder is removed. Partial folders of processes of this host that no
// longer exist (a killed run) are removed when a batch starts.
//
// Videos run as tasks of one task_arena of `threads` threads, at most `parallel` at once (for
// track at most threads - 1: one thread stays free for the trackers' background work); each
// runs its frames in order (decode, then track or flow) and lends the arena's threads to its
// tracker's row tiles and to the dense flow's stripes. A video that fails (cannot be opened, a
// decode error mid-stream) gets status "failed: <message>" and no folder, and is retried by the
// next run; the others go on. `cancel` stops every video at its next frame (status
// "cancelled", no folder).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "flow/dense_lk.hpp"
#include "pipeline/signals.hpp"
#include "tracking/tracker.hpp"

namespace roiflow::pipeline {

enum class BatchJob { Track, Dense };

struct BatchRow {
  std::string video;   // as given
  std::string status;  // "done", "failed: <message>", "cancelled"
  long long frames = 0;
  double fps = 0;        // frames per second of wall time for this video
  double seconds = 0;    // wall time of the run that produced the folder
  bool skipped = false;  // done by an earlier run (its figures are that run's)
  std::string folder;    // <out_dir>/<stem> (exists only when done)
};

struct BatchOptions {
  BatchJob job = BatchJob::Track;
  std::string out_dir;
  tracking::TrackerParams tracker;              // track: every video's (init is refused)
  flow::LkParams lk = flow::LkParams::paper();  // dense
  float max_motion = -1.f;                      // dense: colour saturation; <= 0 per frame
  long long max_frames = 0;                     // per video; 0 = all
  int threads = 0;                              // arena threads; 0 = all hardware threads
  int parallel = 0;  // videos at once; 0 = the most allowed (threads, track: threads - 1)
  const std::atomic<bool>* cancel = nullptr;
  // batch.csv, kept current as videos end (the rows of the videos ended so far, in input order),
  // so a killed batch leaves the rows of what it finished; empty = none.
  std::string csv;
  // Called (from the arena's threads, one call at a time) as each video ends or is skipped, after
  // its row is in `csv`.
  std::function<void(const BatchRow&)> on_row;
};

// The videos of `input`: a directory (its files with a video extension, sorted), a list file
// (.txt or .lst: one path per line, relative to the list's folder; blank lines and lines
// starting with '#' skipped), or any other file, taken as one video. Throws roiflow::Error for
// an input that does not exist or an empty list.
std::vector<std::string> batch_inputs(const std::string& input);

// <stem> of every video, in order; throws roiflow::Error naming two videos with the same stem.
std::vector<std::string> batch_names(const std::vector<std::string>& videos);

// Runs every video not done yet; returns one row per video, in input order. Throws
// roiflow::Error for bad options or an output folder that cannot be created.
std::vector<BatchRow> run_batch(const std::vector<std::string>& videos,
                                const BatchOptions& options);

// batch.csv: `video,status,frames,fps,seconds`, one row per video (fields with a comma or a
// quote are quoted), written atomically.
void write_batch_csv(const std::string& path, const std::vector<BatchRow>& rows);

// The line `roiflow batch` prints as a video ends: "done    V (N frames, F fps) -> FOLDER",
// "skipped V (done earlier)", "failed  V: message", "cancelled  V".
std::string batch_row_line(const BatchRow& row);

struct BatchTally {
  long long ran = 0, skipped = 0, failed = 0, cancelled = 0;
};
BatchTally tally(const std::vector<BatchRow>& rows);

// "batch: N videos: R run, S already done, F failed[, C cancelled][; wrote CSV]".
std::string batch_summary_line(const std::vector<BatchRow>& rows, const std::string& csv);

// How the batch ended, for the CLI: 128 + the signal after SIGINT/SIGTERM (finished videos are
// kept), 1 when a video failed, else 0.
Ending batch_ending(const std::vector<BatchRow>& rows);

}  // namespace roiflow::pipeline
