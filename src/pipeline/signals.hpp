// Ctrl-C for whole runs: while a SignalScope lives, SIGINT and SIGTERM set cancel_flag(), which a
// run given as its cancel flag reads: the source stops, the frames in flight finish, the outputs
// are closed. ending() then says how the run ended, as the CLI reports it: exit code 128 + the
// signal after a signal, 1 after an input that stopped mid-stream, else 0.
//
//   roiflow::pipeline::SignalScope signals;
//   roiflow::video::VideoSource source("synthetic:100");
//   roiflow::pipeline::TrackRunOptions options;
//   options.cancel = roiflow::pipeline::cancel_flag();
//   const auto s = roiflow::pipeline::run_track_video(source, options);
//   const roiflow::pipeline::Ending end = roiflow::pipeline::ending(s.end, s.frames, s.status);
//   if (end.exit_code != 0) std::cerr << end.message << "\n";
#pragma once

#include <atomic>
#include <string>

#include "pipeline/run.hpp"

namespace roiflow::pipeline {

// While alive, SIGINT and SIGTERM set cancel_flag(): a run stops reading, finishes the frames in
// flight, closes its outputs, and the command exits with 128 + the signal.
class SignalScope {
 public:
  SignalScope();
  ~SignalScope();
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

 private:
  void (*previous_int_)(int);
  void (*previous_term_)(int);
};
const std::atomic<bool>* cancel_flag();
int caught_signal();  // 0 when none

// Why a run that a signal or a broken input cut short ended; exit_code 0 when it did not.
struct Ending {
  int exit_code = 0;
  std::string message;
};
Ending ending(RunEnd end, long long frames, const std::string& status);

}  // namespace roiflow::pipeline
