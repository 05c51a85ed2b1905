// Dense LK's row stripes on oneTBB give the serial result, deterministically.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "eval/synthetic.hpp"
#include "flow/dense_lk.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::flow {
namespace {

using eval::make_scene;
using eval::Scene;
using eval::SceneKind;

const cv::Size kSize(320, 240);

double max_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.type(), b.type());
  if (a.size() != b.size() || a.type() != b.type()) return std::numeric_limits<double>::max();
  return cv::norm(a, b, cv::NORM_INF);
}

LkParams with_patch(LkParams p, int patch) {
  p.patch = patch;
  return p;
}

LkParams with_derivative(LkParams p, Derivative d) {
  p.derivative = d;
  return p;
}

struct NamedParams {
  const char* name;
  LkParams params;
};

std::vector<NamedParams> configurations() {
  return {{"paper", LkParams::paper()},
          {"paper patch 9", with_patch(LkParams::paper(), 9)},
          {"accurate", LkParams::accurate()},
          {"accurate patch 11 scharr",
           with_derivative(with_patch(LkParams::accurate(), 11), Derivative::Scharr)}};
}

TEST(DenseLkTest, TbbStripesGiveTheSerialResult) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 12);
  const pipeline::TbbExecutor tbb_exec;
  for (const NamedParams& c : configurations()) {
    for (const cv::Rect region : {cv::Rect(), cv::Rect(40, 30, 200, 150)}) {
      FlowOptions serial_options;
      serial_options.region = region;
      const FlowResult serial = dense_flow(s.frame0, s.frame1, c.params, serial_options);
      const FlowResult parallel = pipeline::run_with_threads(
          2, [&] { return dense_flow(s.frame0, s.frame1, c.params, serial_options, &tbb_exec); });
      EXPECT_EQ(parallel.region, serial.region);
      EXPECT_LT(max_abs_diff(parallel.flow, serial.flow), 1e-5) << c.name << " " << region;
      EXPECT_LT(max_abs_diff(parallel.confidence, serial.confidence), 1e-6)
          << c.name << " " << region;
    }
  }
}

// Whatever the stripes, two parallel runs must agree bit for bit: no shared scratch, no race.
TEST(DenseLkTest, TbbStripesAreDeterministic) {
  const Scene s = make_scene(SceneKind::NonRigid, kSize, 13);
  const pipeline::TbbExecutor tbb_exec;
  for (const NamedParams& c : configurations()) {
    const auto run = [&] {
      return pipeline::run_with_threads(
          2, [&] { return dense_flow(s.frame0, s.frame1, c.params, {}, &tbb_exec); });
    };
    const FlowResult a = run(), b = run();
    EXPECT_EQ(max_abs_diff(a.flow, b.flow), 0.0) << c.name;
    EXPECT_EQ(max_abs_diff(a.confidence, b.confidence), 0.0) << c.name;
  }
}

}  // namespace
}  // namespace roiflow::flow
