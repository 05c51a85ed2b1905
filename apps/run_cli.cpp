// The video runs' shared command-line pieces: source and output options, signals, endings,
// summaries.
#include <csignal>
#include <iostream>
#include <limits>

#include "cli_common.hpp"

namespace roiflow::cli {
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

Ending ending(pipeline::RunEnd end, long long frames, const std::string& status) {
  const int sig = g_signal.load();
  if (end == pipeline::RunEnd::Cancelled && sig != 0) {
    return {128 + sig, std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                           " after " + plural(frames, "frame") +
                           "; outputs hold every frame processed"};
  }
  if (end == pipeline::RunEnd::InputStopped) {
    return {1, "input " + status + "; outputs hold the " + plural(frames, "frame") + " before it"};
  }
  return {};
}

void add_run_outputs(CLI::App& sub, RunOutputs& out, const std::string& video_help) {
  sub.add_option("--out", out.video, video_help)->type_name("VIDEO|DIR");
  sub.add_option("--summary", out.summary, "run summary (frames, fps per stage, ...) as JSON")
      ->type_name("JSON");
  sub.add_flag("!--no-progress", out.progress, "no progress bar on the terminal");
}

void add_source_options(CLI::App& sub, pipeline::SourceOptions& source, int& in_flight) {
  sub.add_option("--start", source.start, "index of the first frame to read")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--max-frames", source.max_frames, "stop after this many frames (0 = all)")
      ->check(CLI::Range(0LL, std::numeric_limits<long long>::max()));
  sub.add_option("--in-flight", in_flight,
                 "frames decoded ahead and in the pipeline at most (0 = 2 x threads + 2)")
      ->check(CLI::Range(0, 1024));
  sub.add_option("--decode-threads", source.decode_threads,
                 "a video's FFmpeg decoder threads (0 = one up to 1280x720, where more cost more "
                 "than they give, else FFmpeg's choice)")
      ->check(CLI::Range(0, 64));
}

void print_track_summary(const std::string& what, const pipeline::TrackSummary& s,
                         const std::vector<std::string>& written) {
  std::cout << what << ": " << s.frames << " frames in " << fixed(s.wall_s, 2) << " s, "
            << fixed(s.fps, 1) << " fps overall, tracker " << fixed(s.tracker_fps, 1) << " fps ("
            << fixed(s.tracker_ms_per_frame, 3) << " ms/frame, decode excluded), mode " << s.mode
            << "\n  global activations " << s.global_activations << ", frames lost "
            << s.lost_frames << ", " << s.threads << " threads\n";
  if (!written.empty()) std::cout << "  wrote " << joined(written) << "\n";
}

std::string joined(const std::vector<std::string>& items) {
  std::string list;
  for (const std::string& item : items)
    list += (list.empty() ? "" : ", ") + item;
  return list;
}

}  // namespace roiflow::cli
