#include "report/run_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using report::RunStats;

TEST(RunStats, ConcurrentAddsSumExactly) {
  RunStats stats;
  constexpr int kThreads = 8;
  constexpr int kAdds = 20000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&stats, t] {
      for (int i = 0; i < kAdds; ++i) {
        // Quarters of a millisecond add up exactly in a double, whatever the order.
        stats.add("decode", 0.25);
        stats.add(t % 2 == 0 ? "lk" : "pyramid", 0.5);
        stats.add_frames(1);
        if (i % 1000 == 0) stats.to_json(1.0);  // readers run alongside writers
      }
    });
  }
  for (std::thread& thread : threads)
    thread.join();

  const nlohmann::ordered_json doc = stats.to_json(2.0);
  EXPECT_EQ(doc["frames"], kThreads * kAdds);
  const auto& stages = doc["stages"];
  EXPECT_EQ(stages["decode"]["calls"], kThreads * kAdds);
  EXPECT_EQ(stages["decode"]["ms_total"].get<double>(), 0.25 * kThreads * kAdds);
  EXPECT_EQ(stages["lk"]["calls"], kThreads / 2 * kAdds);
  EXPECT_EQ(stages["pyramid"]["calls"], kThreads / 2 * kAdds);
  EXPECT_EQ(stages["pyramid"]["ms_total"].get<double>(), 0.5 * kThreads / 2 * kAdds);
  EXPECT_EQ(stages.size(), 3u);
}

TEST(RunStats, JsonHasTotalsMeansAndRatesInFirstUseOrder) {
  RunStats stats;
  stats.add("tracker", 4);
  stats.add("decode", 1);
  stats.add("tracker", 6);
  stats.add("sink", 0);
  stats.add_frames(20);
  stats.add_frames(30);

  const nlohmann::ordered_json doc = stats.to_json(2.5);
  EXPECT_EQ(doc["frames"], 50);
  EXPECT_EQ(doc["wall_s"], 2.5);
  EXPECT_DOUBLE_EQ(doc["fps"].get<double>(), 20.0);

  std::vector<std::string> order;
  for (const auto& [name, value] : doc["stages"].items())
    order.push_back(name);
  EXPECT_EQ(order, (std::vector<std::string>{"tracker", "decode", "sink"}));

  const auto& tracker = doc["stages"]["tracker"];
  EXPECT_EQ(tracker["calls"], 2);
  EXPECT_DOUBLE_EQ(tracker["ms_total"].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(tracker["ms_mean"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(tracker["fps"].get<double>(), 200.0) << "2 calls in 10 ms of busy time";
  EXPECT_TRUE(doc["stages"]["sink"]["fps"].is_null()) << "no busy time, no finite rate";
  EXPECT_TRUE(stats.to_json(0)["fps"].is_null());
}

TEST(RunStats, EmptyRunHasNoStages) {
  const nlohmann::ordered_json doc = RunStats().to_json(1);
  EXPECT_EQ(doc["frames"], 0);
  EXPECT_EQ(doc["fps"], 0.0);
  EXPECT_TRUE(doc["stages"].is_object());
  EXPECT_TRUE(doc["stages"].empty());
}

TEST(RunStats, ConvertsToPlainJsonForCallersThatAddFields) {
  RunStats stats;
  stats.add("lk", 2);
  nlohmann::json summary = stats.to_json(1);
  summary["mode"] = "local";
  EXPECT_EQ(summary["stages"]["lk"]["calls"], 1);
  EXPECT_EQ(summary["mode"], "local");
}

TEST(RunStats, FormatIsATableOfEveryStage) {
  RunStats stats;
  stats.add("pyramid", 3);
  stats.add("a_long_stage_name", 0);
  stats.add_frames(300);
  const std::string text = stats.format(4);
  EXPECT_EQ(text.substr(0, text.find('\n')), "300 frames in 4.00 s: 75.0 fps");
  EXPECT_NE(text.find("stage"), std::string::npos);
  EXPECT_NE(text.find("mean ms"), std::string::npos);
  EXPECT_NE(text.find("pyramid"), std::string::npos);
  EXPECT_NE(text.find("333.3"), std::string::npos) << text;
  EXPECT_NE(text.find("a_long_stage_name"), std::string::npos);
  EXPECT_LT(text.find("pyramid"), text.find("a_long_stage_name"));
}

TEST(RunStats, ScopedTimerAddsOneCall) {
  RunStats stats;
  { report::ScopedTimer timer(stats, "work"); }
  { report::ScopedTimer timer(stats, "work"); }
  const auto work = stats.to_json(1)["stages"]["work"];
  EXPECT_EQ(work["calls"], 2);
  EXPECT_GE(work["ms_total"].get<double>(), 0.0);
}

TEST(RunStats, BadValuesThrowNamingThem) {
  RunStats stats;
  EXPECT_NE(test::error_message([&] { stats.add("lk", -1.5); }).find("-1.5"), std::string::npos);
  EXPECT_NE(test::error_message([&] {
              stats.add("lk", std::numeric_limits<double>::quiet_NaN());
            }).find("nan"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { stats.add("", 1); }).find("empty stage"), std::string::npos);
  EXPECT_NE(test::error_message([&] { report::ScopedTimer timer(stats, ""); }).find("empty stage"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { stats.add_frames(-3); }).find("-3"), std::string::npos);
  EXPECT_NE(test::error_message([&] { stats.to_json(-1); }).find("-1"), std::string::npos);
  EXPECT_TRUE(stats.to_json(1)["stages"].empty()) << "rejected values leave no trace";
}

}  // namespace

TEST(PeakRss, GrowsWhenMemoryIsTouchedAndNeverFalls) {
  const double before = report::peak_rss_mb();
  ASSERT_GT(before, 1.0);  // a running test binary holds more than 1 MiB
  {
    std::vector<unsigned char> block(96u << 20);
    for (std::size_t i = 0; i < block.size(); i += 4096)
      block[i] = static_cast<unsigned char>(i);
    EXPECT_GE(report::peak_rss_mb(), before + 64.0) << "touched 96 MiB";
  }
  EXPECT_GE(report::peak_rss_mb(), before + 64.0) << "the peak is a high-water mark";
}
