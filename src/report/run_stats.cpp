#include "report/run_stats.hpp"

#include <sys/resource.h>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "core/error.hpp"

namespace roiflow::report {
namespace {

void check_stage_name(std::string_view stage) {
  if (stage.empty()) throw Error("run stats: empty stage name");
}

void check_wall(double wall_seconds) {
  if (!(wall_seconds >= 0) || !std::isfinite(wall_seconds)) {
    throw Error("run stats: wall time must be finite and >= 0 s, got " +
                std::to_string(wall_seconds));
  }
}

nlohmann::ordered_json rate(double count, double seconds) {
  if (seconds <= 0) return nullptr;
  return count / seconds;
}

std::string printf_text(const char* format, auto... args) {
  std::string text(static_cast<std::size_t>(std::snprintf(nullptr, 0, format, args...)), '\0');
  std::snprintf(text.data(), text.size() + 1, format, args...);
  return text;
}

}  // namespace

double peak_rss_mb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

double stage_ms_total(const nlohmann::ordered_json& stats, std::string_view stage) {
  const auto& stages = stats.at("stages");
  const auto it = stages.find(std::string(stage));
  return it == stages.end() ? 0.0 : it->at("ms_total").get<double>();
}

nlohmann::ordered_json stages_json(const std::vector<StageTotal>& stages) {
  nlohmann::ordered_json doc = nlohmann::ordered_json::object();
  for (const StageTotal& s : stages) {
    doc[s.name] = {{"calls", s.calls},
                   {"ms_total", s.ms_total},
                   {"ms_mean", s.ms_total / static_cast<double>(s.calls)},
                   {"fps", rate(static_cast<double>(s.calls), s.ms_total / 1000)}};
  }
  return doc;
}

void RunStats::add(std::string_view stage, double ms) {
  check_stage_name(stage);
  if (!(ms >= 0) || !std::isfinite(ms)) {
    throw Error("run stats: time of stage '" + std::string(stage) +
                "' must be finite and >= 0 ms, got " + std::to_string(ms));
  }
  const std::lock_guard lock(mutex_);
  auto it =
      std::find_if(stages_.begin(), stages_.end(), [&](const Stage& s) { return s.name == stage; });
  if (it == stages_.end()) it = stages_.insert(stages_.end(), Stage{std::string(stage)});
  ++it->calls;
  it->ms_total += ms;
}

void RunStats::add_frames(long long n) {
  if (n < 0) throw Error("run stats: frame count must be >= 0, got " + std::to_string(n));
  const std::lock_guard lock(mutex_);
  frames_ += n;
}

nlohmann::ordered_json RunStats::to_json(double wall_seconds) const {
  check_wall(wall_seconds);
  const std::lock_guard lock(mutex_);
  nlohmann::ordered_json doc = {{"frames", frames_},
                                {"wall_s", wall_seconds},
                                {"fps", rate(static_cast<double>(frames_), wall_seconds)}};
  doc["stages"] = stages_json(stages_);
  return doc;
}

std::vector<StageTotal> RunStats::totals() const {
  const std::lock_guard lock(mutex_);
  return stages_;
}

std::string RunStats::format(double wall_seconds) const {
  check_wall(wall_seconds);
  const std::lock_guard lock(mutex_);
  std::string text = printf_text("%lld frames in %.2f s", frames_, wall_seconds);
  text += wall_seconds > 0
              ? printf_text(": %.1f fps\n", static_cast<double>(frames_) / wall_seconds)
              : std::string("\n");
  if (stages_.empty()) return text;
  int width = 5;  // "stage"
  for (const Stage& s : stages_)
    width = std::max(width, static_cast<int>(s.name.size()));
  text += printf_text("%-*s %10s %12s %10s %10s\n", width, "stage", "calls", "total ms", "mean ms",
                      "fps");
  for (const Stage& s : stages_) {
    const double mean = s.ms_total / static_cast<double>(s.calls);
    text +=
        printf_text("%-*s %10lld %12.2f %10.3f ", width, s.name.c_str(), s.calls, s.ms_total, mean);
    text += s.ms_total > 0
                ? printf_text("%10.1f\n", static_cast<double>(s.calls) * 1000 / s.ms_total)
                : printf_text("%10s\n", "-");
  }
  return text;
}

ScopedTimer::ScopedTimer(RunStats& stats, std::string_view stage)
    : stats_(stats), stage_(stage), start_(std::chrono::steady_clock::now()) {
  check_stage_name(stage);
}

ScopedTimer::~ScopedTimer() {
  const std::chrono::duration<double, std::milli> elapsed =
      std::chrono::steady_clock::now() - start_;
  stats_.add(stage_, elapsed.count());
}

}  // namespace roiflow::report
