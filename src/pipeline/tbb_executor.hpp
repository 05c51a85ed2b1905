// TbbExecutor — the flow core's row stripes on oneTBB, and a scope that fixes the thread count.
//
//   using namespace roiflow;
//   pipeline::TbbExecutor tbb_exec;
//   flow::DenseLK lk(flow::LkParams::paper(), &tbb_exec);
//   auto r = pipeline::run_with_threads(2, [&] { return lk.calc(frame_t, frame_t1); });
//
// TbbExecutor::for_range runs in whatever task_arena its caller is in, so it owns no threads and
// one instance can serve every caller. run_with_threads(n, f) runs f in a fresh arena of n
// threads and, for the duration of the call, sets OpenCV's own thread count to n as well: the
// pyramid, warps and filters OpenCV runs for us parallelise on their own, so "one thread" is
// only true when both are pinned.
#pragma once

#include <oneapi/tbb/task_arena.h>

#include <functional>
#include <utility>

#include "core/executor.hpp"

namespace roiflow::pipeline {

inline constexpr int kMaxThreads = 256;
int default_threads();  // the hardware's thread count, within 1..kMaxThreads

class TbbExecutor final : public Executor {
 public:
  // Every sub-range is at least `grain` long unless [begin, end) itself is shorter; grain < 1
  // counts as 1. An exception thrown by body cancels the remaining sub-ranges and is rethrown.
  void for_range(int begin, int end, int grain,
                 const std::function<void(int, int)>& body) const override;
  // The caller's arena's thread count.
  int concurrency() const override;
  // With more than one thread: `job` as a task of the caller's arena (a tbb::task_group), which
  // an idle thread takes while the caller goes on. The job must be waited for before that
  // arena ends (run_tracking waits for the tracker's through TrackStep::drain).
  std::unique_ptr<Job> start(std::function<void()> job) const override;
};

// Holds OpenCV at `threads` threads and owns an arena of `threads` slots while it lives.
// OpenCV's thread count is process-wide: use one ThreadScope at a time, from one thread.
class ThreadScope {
 public:
  // Throws roiflow::Error unless 1 <= threads <= kMaxThreads.
  explicit ThreadScope(int threads);
  ~ThreadScope();
  ThreadScope(const ThreadScope&) = delete;
  ThreadScope& operator=(const ThreadScope&) = delete;

  // Runs f on the calling thread inside the arena; returns what f returns, rethrows what it
  // throws.
  template <class F>
  decltype(auto) run(F&& f) {
    return arena_.execute(std::forward<F>(f));
  }

 private:
  int previous_cv_threads_;
  tbb::task_arena arena_;
};

template <class F>
decltype(auto) run_with_threads(int threads, F&& f) {
  ThreadScope scope(threads);
  return scope.run(std::forward<F>(f));
}

}  // namespace roiflow::pipeline
