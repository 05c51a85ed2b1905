#include "report/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace roiflow::report {
namespace {

constexpr double kRedrawInterval = 0.1;  // seconds: smooth to the eye, invisible in the profile
constexpr int kBarWidth = 20;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// "45s", "3m07s", "2h05m": as precise as a person reading a moving estimate needs.
std::string duration_text(double seconds) {
  const long long s = std::llround(std::max(0.0, seconds));
  char text[48];
  if (s < 60) {
    std::snprintf(text, sizeof text, "%llds", s);
  } else if (s < 3600) {
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, s / 60 % 60);
  }
  return text;
}

}  // namespace

Progress::Progress(std::ostream& out, long long total, bool enabled, Clock clock)
    : out_(out),
      total_(total),
      enabled_(enabled),
      clock_(clock ? std::move(clock) : Clock(steady_seconds)) {
  if (enabled_) start_ = clock_();
}

Progress::~Progress() {
  if (!drawn_) return;
  try {
    finish();
  } catch (...) {
    // A progress line is not worth terminating for.
  }
}

void Progress::update(long long frames_done) {
  if (!enabled_ || finished_) return;
  done_ = frames_done;
  const double now = clock_();
  if (drawn_ && now - last_draw_ < kRedrawInterval) return;
  draw(now, false);
}

void Progress::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  draw(clock_(), true);
  out_ << '\n' << std::flush;
}

void Progress::draw(double now, bool final) {
  const double elapsed = now - start_;
  const double fps = elapsed > 0 ? static_cast<double>(done_) / elapsed : 0;
  char text[160];
  std::string line;
  if (total_ > 0) {
    const double fraction = std::clamp(static_cast<double>(done_) / total_, 0.0, 1.0);
    const int filled = static_cast<int>(fraction * kBarWidth);
    line.push_back('[');  // not line = "[": GCC 12 warns (-Wrestrict) on that under ASan
    line.append(filled, '#');
    line.append(kBarWidth - filled, '.');
    line += "] ";
    std::snprintf(text, sizeof text, "%lld/%lld frames", done_, total_);
  } else {
    std::snprintf(text, sizeof text, "%lld frames", done_);
  }
  line += text;
  if (fps > 0) {
    std::snprintf(text, sizeof text, "  %.1f fps", fps);
    line += text;
  }
  if (final) {
    line += "  in ";
    line += duration_text(elapsed);
  } else if (total_ > 0 && fps > 0 && done_ < total_) {
    line += "  ETA ";
    line += duration_text(static_cast<double>(total_ - done_) / fps);
  }
  const std::size_t width = line.size();
  if (width < last_width_) line.append(last_width_ - width, ' ');
  last_width_ = width;
  out_ << '\r' << line << std::flush;
  last_draw_ = now;
  drawn_ = true;
}

bool Progress::stderr_is_terminal() {
  return isatty(STDERR_FILENO) == 1;
}

}  // namespace roiflow::report
