// Dense flow of a synthetic translated pair through the installed headers and libraries; exits
// 0 when the flow is within 0.2 px of the exact one, 1 otherwise.
#include <cstdio>

#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "flow/synthetic.hpp"
#ifdef CONSUMER_WITH_PIPELINE
#include "pipeline/tbb_executor.hpp"
#endif

int main() {
  using namespace roiflow;
  const flow::Scene scene = flow::make_translation({160, 120}, {1.25f, -0.5f});
#ifdef CONSUMER_WITH_PIPELINE
  const pipeline::TbbExecutor tbb;
  const flow::Executor* executor = &tbb;
#else
  const flow::Executor* executor = nullptr;
#endif
  flow::DenseLK lk(flow::LkParams::paper(), executor);
  const flow::FlowResult result = lk.calc(scene.frame0, scene.frame1);
  const flow::FlowErrors errors = flow::flow_errors(result.flow, scene.flow);
  std::printf("installed roiflow: EPE %.4f px over %lld pixels\n", errors.epe,
              static_cast<long long>(errors.pixels));
  return errors.pixels > 0 && errors.epe < 0.2 ? 0 : 1;
}
