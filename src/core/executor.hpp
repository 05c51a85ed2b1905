// Executor — how the flow core runs independent row stripes.
//
//   roiflow::SerialExecutor serial;            // the default: one thread
//   dense_flow(a, b, params, {}, &serial);
//
// src/flow knows no threads. A caller that wants parallel stripes (the pipeline does it with
// tbb::parallel_for) passes an Executor whose for_range may run body(begin, end) on disjoint
// sub-ranges of [begin, end) concurrently. Bodies never share writable state.
//
// start(job) runs a job beside the caller (the tracker's background-model refresh): the caller
// goes on and calls wait() on the handle before it touches what the job touches again.
#pragma once

#include <functional>
#include <memory>

namespace roiflow {

// A job started by Executor::start. wait() returns once the job has run and rethrows what it
// threw; a handle destroyed without wait() still waits (and drops the exception).
class Job {
 public:
  virtual ~Job() = default;
  virtual void wait() = 0;
};

class Executor {
 public:
  virtual ~Executor() = default;
  // Calls body on disjoint sub-ranges covering [begin, end), each at least `grain` long when
  // the range allows it. Returns when all calls have returned.
  virtual void for_range(int begin, int end, int grain,
                         const std::function<void(int, int)>& body) const = 0;
  // How many bodies may run at once; 1 lets the caller pick a serial schedule instead.
  virtual int concurrency() const = 0;
  // Starts `job` to run beside the caller. This default runs it at once, on the caller's
  // thread (exceptions propagate from here), and returns a finished handle.
  virtual std::unique_ptr<Job> start(std::function<void()> job) const {
    job();
    return std::make_unique<DoneJob>();
  }

 private:
  struct DoneJob final : Job {
    void wait() override {}
  };
};

class SerialExecutor final : public Executor {
 public:
  void for_range(int begin, int end, int /*grain*/,
                 const std::function<void(int, int)>& body) const override {
    if (begin < end) body(begin, end);
  }
  int concurrency() const override { return 1; }
};

}  // namespace roiflow
