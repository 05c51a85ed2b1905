// Where a run's time went, per stage, from any number of threads at once: stages in first-use
// order with their calls, total and mean milliseconds and the rate each could sustain alone,
// as JSON or as a table (docs/REPORTS.md); and the process's peak memory.
//
//   roiflow::report::RunStats stats;
//   {
//     roiflow::report::ScopedTimer timer(stats, "pyramid");  // adds its lifetime on scope exit
//   }
//   stats.add("lk", 3.2);  // or add milliseconds yourself
//   stats.add_frames(1);
//   nlohmann::ordered_json summary = stats.to_json(/*wall_seconds=*/0.01);
//   std::cerr << stats.format(0.01) << roiflow::report::peak_rss_mb() << " MiB\n";
#pragma once

#include <chrono>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace roiflow::report {

// The process's peak resident set size so far, in MiB (getrusage ru_maxrss); 0 where the
// platform does not report it. Monotonic: a long run shows whether memory stays flat.
double peak_rss_mb();

// One stage's totals, as RunStats::totals() reports them.
struct StageTotal {
  std::string name;
  long long calls = 0;
  double ms_total = 0;
};

// {"<name>": {"calls", "ms_total", "ms_mean", "fps"}, ...}, the "stages" object of to_json.
nlohmann::ordered_json stages_json(const std::vector<StageTotal>& stages);

// The total milliseconds of `stage` in a to_json() document (its "stages" object); 0 when the
// stage never ran.
double stage_ms_total(const nlohmann::ordered_json& stats, std::string_view stage);

class RunStats {
 public:
  void add(std::string_view stage, double ms);
  void add_frames(long long n);

  std::vector<StageTotal> totals() const;  // first-use order
  nlohmann::ordered_json to_json(double wall_seconds) const;
  // A table for people:
  //   300 frames in 4.21 s: 71.3 fps
  //   stage        calls    total ms   mean ms      fps
  //   pyramid        300      812.40     2.708    369.3
  std::string format(double wall_seconds) const;

 private:
  using Stage = StageTotal;

  mutable std::mutex mutex_;
  std::vector<Stage> stages_;  // first-use order; a handful, so a linear search is fastest
  long long frames_ = 0;
};

// Adds the time from construction to destruction to `stage` of `stats`, which must outlive it.
class ScopedTimer {
 public:
  ScopedTimer(RunStats& stats, std::string_view stage);
  ~ScopedTimer();
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  RunStats& stats_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace roiflow::report
