// Executor — how the flow core runs independent row stripes.
//
//   roiflow::flow::SerialExecutor serial;            // the default: one thread
//   dense_flow(a, b, params, {}, &serial);
//
// src/flow knows no threads. A caller that wants parallel stripes (the pipeline does it with
// tbb::parallel_for) passes an Executor whose for_range may run body(begin, end) on disjoint
// sub-ranges of [begin, end) concurrently. Bodies never share writable state.
#pragma once

#include <functional>

namespace roiflow::flow {

class Executor {
 public:
  virtual ~Executor() = default;
  // Calls body on disjoint sub-ranges covering [begin, end), each at least `grain` long when
  // the range allows it. Returns when all calls have returned.
  virtual void for_range(int begin, int end, int grain,
                         const std::function<void(int, int)>& body) const = 0;
  // How many bodies may run at once; 1 lets the caller pick a serial schedule instead.
  virtual int concurrency() const = 0;
};

class SerialExecutor final : public Executor {
 public:
  void for_range(int begin, int end, int /*grain*/,
                 const std::function<void(int, int)>& body) const override {
    if (begin < end) body(begin, end);
  }
  int concurrency() const override { return 1; }
};

}  // namespace roiflow::flow
