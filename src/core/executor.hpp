// How the flow core runs independent row stripes, without knowing threads: a caller that wants
// them parallel passes an Executor whose for_range may run body(begin, end) on disjoint
// sub-ranges of [begin, end) at once (the pipeline's TbbExecutor does). start(job) runs a job
// beside the caller, who calls wait() on the handle before touching what the job touches.
// SerialExecutor runs everything on the caller's thread.
//
//   const roiflow::SerialExecutor serial;
//   std::vector<int> rows(480);
//   serial.for_range(0, 480, 16, [&](int begin, int end) {
//     for (int y = begin; y < end; ++y) rows[y] = y;
//   });
//   serial.start([] { std::cout << "side job\n"; })->wait();
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
