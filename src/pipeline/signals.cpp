#include "pipeline/signals.hpp"

#include <csignal>

namespace roiflow::pipeline {

namespace {

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};

extern "C" void on_signal(int signal) {
  g_signal.store(signal);
  g_cancel.store(true);
}

std::string plural(long long n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

}  // namespace

SignalScope::SignalScope()
    : previous_int_(std::signal(SIGINT, on_signal)),
      previous_term_(std::signal(SIGTERM, on_signal)) {}

SignalScope::~SignalScope() {
  std::signal(SIGINT, previous_int_);
  std::signal(SIGTERM, previous_term_);
}

const std::atomic<bool>* cancel_flag() {
  return &g_cancel;
}
int caught_signal() {
  return g_signal.load();
}

Ending ending(RunEnd end, long long frames, const std::string& status) {
  const int sig = g_signal.load();
  if (end == RunEnd::Cancelled && sig != 0) {
    return {128 + sig, std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                           " after " + plural(frames, "frame") +
                           "; outputs hold every frame processed"};
  }
  if (end == RunEnd::InputStopped) {
    return {1, "input " + status + "; outputs hold the " + plural(frames, "frame") + " before it"};
  }
  return {};
}

}  // namespace roiflow::pipeline
