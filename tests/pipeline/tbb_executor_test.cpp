#include "pipeline/tbb_executor.hpp"

#include <gtest/gtest.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace roiflow::pipeline {
namespace {

// Counts, per index, how many body calls covered it, plus the shortest sub-range seen.
struct Coverage {
  explicit Coverage(int n) : hits(std::make_unique<std::atomic<int>[]>(n)) {}
  std::unique_ptr<std::atomic<int>[]> hits;
  std::atomic<int> calls{0};
  std::atomic<int> shortest{1 << 30};

  void record(int b, int e, int offset) {
    calls.fetch_add(1);
    for (int i = b; i < e; ++i)
      hits[i - offset].fetch_add(1);
    int seen = shortest.load();
    while (e - b < seen && !shortest.compare_exchange_weak(seen, e - b)) {
    }
  }
};

TEST(TbbExecutorTest, CoversRangeExactlyOnceWithDisjointSubRanges) {
  constexpr int kBegin = -37;
  constexpr int kEnd = 1000;
  constexpr int kGrain = 7;
  Coverage cov(kEnd - kBegin);
  const TbbExecutor exec;
  run_with_threads(2, [&] {
    exec.for_range(kBegin, kEnd, kGrain, [&](int b, int e) {
      EXPECT_LT(b, e);
      EXPECT_GE(b, kBegin);
      EXPECT_LE(e, kEnd);
      cov.record(b, e, kBegin);
    });
  });
  for (int i = 0; i < kEnd - kBegin; ++i)
    EXPECT_EQ(cov.hits[i].load(), 1) << "index " << kBegin + i;
  // Exactly-once coverage by several calls is only possible if the calls were disjoint; one
  // call would mean the range was never split.
  EXPECT_GT(cov.calls.load(), 1);
  EXPECT_GE(cov.shortest.load(), kGrain);
}

TEST(TbbExecutorTest, RangeShorterThanGrainIsOneCall) {
  Coverage cov(5);
  const TbbExecutor exec;
  run_with_threads(2,
                   [&] { exec.for_range(0, 5, 16, [&](int b, int e) { cov.record(b, e, 0); }); });
  EXPECT_EQ(cov.calls.load(), 1);
  EXPECT_EQ(cov.shortest.load(), 5);
}

TEST(TbbExecutorTest, OneThreadIsOneCall) {
  Coverage cov(500);
  const TbbExecutor exec;
  run_with_threads(1,
                   [&] { exec.for_range(0, 500, 1, [&](int b, int e) { cov.record(b, e, 0); }); });
  EXPECT_EQ(cov.calls.load(), 1);
  EXPECT_EQ(cov.shortest.load(), 500);
}

TEST(TbbExecutorTest, EmptyRangeCallsNothing) {
  const TbbExecutor exec;
  std::atomic<int> calls{0};
  exec.for_range(3, 3, 1, [&](int, int) { calls.fetch_add(1); });
  exec.for_range(5, 2, 1, [&](int, int) { calls.fetch_add(1); });
  EXPECT_EQ(calls.load(), 0);
}

TEST(TbbExecutorTest, RunWithThreadsSetsArenaAndOpenCvThreads) {
  const int cv_before = cv::getNumThreads();
  int inside_arena = 0;
  int inside_cv = 0;
  const int result = run_with_threads(2, [&] {
    inside_arena = tbb::this_task_arena::max_concurrency();
    inside_cv = cv::getNumThreads();
    return 42;
  });
  EXPECT_EQ(result, 42);
  EXPECT_EQ(inside_arena, 2);
  EXPECT_EQ(inside_cv, 2);
  EXPECT_EQ(cv::getNumThreads(), cv_before);
}

TEST(TbbExecutorTest, BadThreadCountThrows) {
  for (int bad : {0, -1, kMaxThreads + 1}) {
    EXPECT_THROW(run_with_threads(bad, [] {}), roiflow::Error) << bad;
  }
  const int cv_before = cv::getNumThreads();
  try {
    run_with_threads(-3, [] {});
    FAIL() << "no exception";
  } catch (const roiflow::Error& e) {
    EXPECT_NE(std::string(e.what()).find("-3"), std::string::npos) << e.what();
  }
  EXPECT_EQ(cv::getNumThreads(), cv_before);
}

TEST(TbbExecutorTest, ExceptionInBodyPropagates) {
  const TbbExecutor exec;
  const int cv_before = cv::getNumThreads();
  EXPECT_THROW(run_with_threads(2,
                                [&] {
                                  exec.for_range(0, 1000, 1, [](int b, int e) {
                                    if (b <= 500 && 500 < e) throw std::out_of_range("row 500");
                                  });
                                }),
               std::out_of_range);
  EXPECT_EQ(cv::getNumThreads(), cv_before);
  // Outside any explicit arena too, and with the single-thread shortcut.
  EXPECT_THROW(exec.for_range(0, 10, 1, [](int, int) { throw roiflow::Error("boom"); }),
               roiflow::Error);
  EXPECT_THROW(
      run_with_threads(
          1, [&] { exec.for_range(0, 10, 1, [](int, int) { throw std::logic_error("x"); }); }),
      std::logic_error);
}

}  // namespace
}  // namespace roiflow::pipeline
