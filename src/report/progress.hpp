// Progress: a one-line progress bar for long runs, redrawn in place on a terminal.
//
//   using roiflow::report::Progress;
//   Progress progress(std::cerr, source.frame_count_hint(), Progress::stderr_is_terminal());
//   for (...) progress.update(frames_done);     // cheap: redraws at most ~10 times a second
//   progress.finish();                          // the final state, then a newline
//
// The line, rewritten after a carriage return:
//   [#########...........] 120/300 frames  87.3 fps  ETA 2s     (total known)
//   120 frames  87.3 fps                                        (total unknown: <= 0)
// finish() replaces the ETA by the elapsed time ("in 3s"). The rate is the average since
// construction. A disabled Progress prints nothing at all, so callers need no `if` around it
// (disable it when the stream is not a terminal: a log file full of carriage returns helps no
// one). The destructor finishes a line that was started, so an error message printed after an
// exception starts on a line of its own. Not thread-safe: one caller at a time.
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>

namespace roiflow::report {

class Progress {
 public:
  // Seconds on a monotonic clock; the default is std::chrono::steady_clock. Tests inject their
  // own to make the redraw rate and the numbers deterministic.
  using Clock = std::function<double()>;

  Progress(std::ostream& out, long long total, bool enabled, Clock clock = {});
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(long long frames_done);
  // Idempotent; update() after finish() is ignored.
  void finish();

  static bool stderr_is_terminal();

 private:
  void draw(double now, bool final);

  std::ostream& out_;
  long long total_;
  bool enabled_;
  Clock clock_;
  double start_ = 0;
  double last_draw_ = 0;
  bool drawn_ = false;
  bool finished_ = false;
  long long done_ = 0;
  std::size_t last_width_ = 0;  // to blank the rest of a longer previous line
};

}  // namespace roiflow::report
