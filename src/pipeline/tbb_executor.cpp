#include "pipeline/tbb_executor.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>

#include <algorithm>
#include <cstddef>
#include <opencv2/core/utility.hpp>
#include <string>
#include <thread>

#include "core/error.hpp"

namespace roiflow::pipeline {

namespace {

class TbbJob final : public Job {
 public:
  explicit TbbJob(std::function<void()> job) {
    tbb::this_task_arena::enqueue(group_.defer(std::move(job)));
  }
  ~TbbJob() noexcept override {
    try {
      group_.wait();
    } catch (...) {  // NOLINT(bugprone-empty-catch): the owner did not ask for the outcome
    }
  }
  void wait() override { group_.wait(); }

 private:
  tbb::task_group group_;
};

int validated_thread_count(int threads) {
  if (threads < 1 || threads > kMaxThreads) {
    throw Error("thread count must be in 1.." + std::to_string(kMaxThreads) + ", got " +
                std::to_string(threads));
  }
  return threads;
}

}  // namespace

void TbbExecutor::for_range(int begin, int end, int grain,
                            const std::function<void(int, int)>& body) const {
  if (begin >= end) return;
  // With one thread there is nobody to share with, and every extra stripe costs the flow core
  // its halo rows again.
  if (tbb::this_task_arena::max_concurrency() == 1) {
    body(begin, end);
    return;
  }
  // blocked_range halves a range whose size exceeds its grainsize, so a grainsize of
  // 2 * grain - 1 is what keeps both halves at least `grain` long.
  const auto min_size = static_cast<std::size_t>(std::max(grain, 1));
  const tbb::blocked_range<int> range(begin, end, 2 * min_size - 1);
  // auto_partitioner, not simple_partitioner: stripes cost the same per row, so a few big
  // chunks per thread balance as well as many small ones, and every extra stripe repeats the
  // flow core's per-stripe setup. `grain` stays a floor, not the chunk size.
  // Isolated: while this thread waits for its stripes it must not pick up another node's task
  // (a frame to decode, a pyramid), which would hold up the serial node it is running for.
  // Its own isolated task_group_context: a graph that is being cancelled (another node threw)
  // must not silently skip some stripes of a pass already running, which would leave a result
  // half computed and the stripes' waits on a cancelled tree. An exception from `body` still
  // propagates from parallel_for.
  tbb::this_task_arena::isolate([&] {
    tbb::task_group_context stripes(tbb::task_group_context::isolated);
    tbb::parallel_for(
        range, [&body](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); },
        tbb::auto_partitioner(), stripes);
  });
}

int TbbExecutor::concurrency() const {
  return tbb::this_task_arena::max_concurrency();
}

std::unique_ptr<Job> TbbExecutor::start(std::function<void()> job) const {
  if (tbb::this_task_arena::max_concurrency() == 1) return Executor::start(std::move(job));
  return std::make_unique<TbbJob>(std::move(job));
}

ThreadScope::ThreadScope(int threads)
    : previous_cv_threads_(cv::getNumThreads()), arena_(validated_thread_count(threads)) {
  cv::setNumThreads(threads);
}

ThreadScope::~ThreadScope() {
  cv::setNumThreads(previous_cv_threads_);
}

int default_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxThreads);
}

}  // namespace roiflow::pipeline
