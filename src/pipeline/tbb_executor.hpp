// The flow core's row stripes on oneTBB, and a scope that fixes the thread count. TbbExecutor
// runs in whatever task_arena its caller is in (it owns no threads; one instance serves every
// caller); run_with_threads(n, f) runs f in a fresh arena of n threads and pins OpenCV's own
// thread count to n for the call, so that "one thread" means one.
//
//   const roiflow::pipeline::TbbExecutor tbb_exec;
//   roiflow::flow::DenseLK lk(roiflow::flow::LkParams::paper(), &tbb_exec);
//   const auto r = roiflow::pipeline::run_with_threads(2, [&] { return lk.calc(bgr, bgr); });
//   std::cout << r.flow.size() << " on " << roiflow::pipeline::default_threads() << " threads\n";
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
