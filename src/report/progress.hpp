// A one-line progress bar for long runs, redrawn in place on a terminal at most ~10 times a
// second ("[####......] 120/300 frames  87.3 fps  ETA 2s"); a disabled one prints nothing, so
// callers need no `if` around it. Not thread-safe (docs/REPORTS.md).
//
//   using roiflow::report::Progress;
//   Progress progress(std::cerr, 300, Progress::stderr_is_terminal());
//   for (long long done = 1; done <= 300; ++done) progress.update(done);
//   progress.finish();  // the final state, then a newline
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
