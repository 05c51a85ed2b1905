// Dense LK's row bands on oneTBB give the serial result bit for bit, and the executor belongs to
// the DenseLK object, not to the options.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "eval/synthetic.hpp"
#include "flow/dense_lk.hpp"
#include "lk_configurations.hpp"
#include "pipeline/tbb_executor.hpp"
#include "test_util.hpp"

namespace roiflow::flow {
namespace {

using eval::make_scene;
using eval::Scene;
using eval::SceneKind;

const cv::Size kSize(320, 240);

// Bands start on rows where the window sums start afresh and recompute the rows their later
// iterations read: the split changes nothing, to the last bit.
TEST(DenseLkTest, TbbBandsGiveTheSerialResultBitForBit) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 12);
  const pipeline::TbbExecutor tbb_exec;
  for (const test::NamedParams& c : test::thread_configurations()) {
    for (const cv::Rect region : {cv::Rect(), cv::Rect(40, 30, 200, 150)}) {
      FlowOptions options;
      options.region = region;
      const FlowResult serial = dense_flow(s.frame0, s.frame1, c.params, options);
      for (const int threads : {2, 3, 5}) {
        const FlowResult parallel = pipeline::run_with_threads(
            threads, [&] { return dense_flow(s.frame0, s.frame1, c.params, options, &tbb_exec); });
        EXPECT_EQ(parallel.region, serial.region);
        EXPECT_EQ(test::max_abs_diff(parallel.flow, serial.flow), 0.0)
            << c.name << " " << region << " " << threads;
        EXPECT_EQ(test::max_abs_diff(parallel.confidence, serial.confidence), 0.0)
            << c.name << " " << region << " " << threads;
      }
    }
  }
}

// Two parallel runs agree bit for bit: no shared scratch, no race.
TEST(DenseLkTest, TbbBandsAreDeterministic) {
  const Scene s = make_scene(SceneKind::NonRigid, kSize, 13);
  const pipeline::TbbExecutor tbb_exec;
  for (const test::NamedParams& c : test::thread_configurations()) {
    const auto run = [&] {
      return pipeline::run_with_threads(
          2, [&] { return dense_flow(s.frame0, s.frame1, c.params, {}, &tbb_exec); });
    };
    const FlowResult a = run(), b = run();
    EXPECT_EQ(test::max_abs_diff(a.flow, b.flow), 0.0) << c.name;
    EXPECT_EQ(test::max_abs_diff(a.confidence, b.confidence), 0.0) << c.name;
  }
}

TEST(DenseLkTest, ExecutorIsPartOfTheObjectNotTheOptions) {
  const Scene s = make_scene(SceneKind::MovingObject, kSize, 6);
  const pipeline::TbbExecutor tbb;
  for (const test::NamedParams& c : test::thread_configurations()) {
    const FlowResult serial = DenseLK(c.params).calc(s.frame0, s.frame1);
    DenseLK lk(c.params, &tbb);
    EXPECT_EQ(lk.executor(), &tbb);
    const FlowResult parallel =
        pipeline::run_with_threads(2, [&] { return lk.calc(s.frame0, s.frame1); });
    EXPECT_EQ(test::max_abs_diff(parallel.flow, serial.flow), 0.0) << c.name;
    EXPECT_EQ(test::max_abs_diff(parallel.confidence, serial.confidence), 0.0) << c.name;
    lk.set_executor(nullptr);
    EXPECT_EQ(test::max_abs_diff(lk.calc(s.frame0, s.frame1).flow, serial.flow), 0.0) << c.name;
    // Through the OpenCV interface too.
    const cv::Ptr<cv::DenseOpticalFlow> of = createDenseLK(c.params, &tbb);
    cv::Mat flow;
    pipeline::run_with_threads(2, [&] { of->calc(s.frame0, s.frame1, flow); });
    EXPECT_EQ(test::max_abs_diff(flow, serial.flow), 0.0) << c.name;
  }
}

}  // namespace
}  // namespace roiflow::flow
