// The LK parameter sets the dense LK tests run every property over: the presets, a smaller and
// a larger patch, Scharr derivatives, and the 4-level `paper` variant of docs/PERFORMANCE.md.
//
//   for (const roiflow::test::NamedParams& c : roiflow::test::lk_configurations()) {
//     SCOPED_TRACE(c.name);
//     roiflow::flow::DenseLK lk(c.params);
//   }
//
// Under ThreadSanitizer (which instruments every load and store of the kernels) the thread tests
// take thread_configurations(): the paper preset and the accurate one (the paper's method and the
// project's tuned one); the other sets change the arithmetic more than the threading, and keep
// their run in the release and AddressSanitizer builds.
#pragma once

#include <vector>

#include "flow/dense_lk.hpp"

namespace roiflow::test {

inline flow::LkParams with_patch(flow::LkParams p, int patch) {
  p.patch = patch;
  return p;
}

inline flow::LkParams with_derivative(flow::LkParams p, flow::Derivative d) {
  p.derivative = d;
  return p;
}

// paper on 4 levels with 1 iteration at the finest (docs/PERFORMANCE.md, variant l4i1r).
inline flow::LkParams paper_l4i1r() {
  flow::LkParams p = flow::LkParams::paper();
  p.levels = 4;
  p.finest_iterations = 1;
  p.mask_outside = true;
  p.robust_scale = 0.04;
  return p;
}

struct NamedParams {
  const char* name;
  flow::LkParams params;
};

inline std::vector<NamedParams> lk_configurations() {
  using flow::LkParams;
  return {{"paper", LkParams::paper()},
          {"paper patch 9", with_patch(LkParams::paper(), 9)},
          {"paper l4i1r", paper_l4i1r()},
          {"accurate", LkParams::accurate()},
          {"accurate patch 11 scharr",
           with_derivative(with_patch(LkParams::accurate(), 11), flow::Derivative::Scharr)}};
}

// The sets a test over thread counts runs: all of lk_configurations(), or under ThreadSanitizer
// (GCC's __SANITIZE_THREAD__) the two presets only.
inline std::vector<NamedParams> thread_configurations() {
#ifdef __SANITIZE_THREAD__
  return {{"paper", flow::LkParams::paper()}, {"accurate", flow::LkParams::accurate()}};
#else
  return lk_configurations();
#endif
}

}  // namespace roiflow::test
