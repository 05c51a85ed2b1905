// DenseLK (the flow object that owns its workspace), its cv::DenseOpticalFlow face
// createDenseLK, and FlowOptions::initial_flow.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/synthetic.hpp"
#include "flow/dense_lk.hpp"
#include "flow/lk_kernels.hpp"
#include "flow/metrics.hpp"
#include "flow/pyramid.hpp"
#include "test_util.hpp"

namespace roiflow::flow {
namespace {

using eval::make_scene;
using eval::make_translation;
using eval::Scene;
using eval::SceneKind;
using test::error_message;

const cv::Size kObjectSceneSize(160, 120);

std::vector<LkParams> parameter_sets() {
  LkParams scharr = LkParams::accurate();
  scharr.patch = 11;
  scharr.derivative = Derivative::Scharr;
  return {LkParams::paper(), LkParams::accurate(), scharr};
}

// Three textures moving alike as the B, G and R planes of a colour pair.
Scene colour_scene() {
  Scene planes[3];
  std::vector<cv::Mat> f0, f1;
  for (int c = 0; c < 3; ++c) {
    planes[c] = make_scene(SceneKind::Rotation, kObjectSceneSize, 20 + c);
    f0.push_back(planes[c].frame0);
    f1.push_back(planes[c].frame1);
  }
  Scene s;
  cv::merge(f0, s.frame0);
  cv::merge(f1, s.frame1);
  s.flow = planes[0].flow;
  return s;
}

TEST(DenseLkObjectTest, CalcEqualsDenseFlowBitForBitAndReusesItsWorkspace) {
  const Scene s = make_scene(SceneKind::NonRigid, kObjectSceneSize, 3);
  const Scene other = make_scene(SceneKind::Zoom, {96, 80}, 4);
  for (const LkParams& params : parameter_sets()) {
    DenseLK lk(params);
    for (const cv::Rect region : {cv::Rect(), cv::Rect(30, 20, 70, 50)}) {
      FlowOptions options;
      options.region = region;
      const FlowResult expected = dense_flow(s.frame0, s.frame1, params, options);
      // Twice on the same buffers, then another size in between and back.
      for (int round = 0; round < 2; ++round) {
        const FlowResult r = lk.calc(s.frame0, s.frame1, options);
        EXPECT_EQ(test::max_abs_diff(r.flow, expected.flow), 0.0) << round;
        EXPECT_EQ(test::max_abs_diff(r.confidence, expected.confidence), 0.0) << round;
        EXPECT_EQ(r.region, expected.region);
      }
      const FlowResult small = lk.calc(other.frame0, other.frame1);
      EXPECT_EQ(test::max_abs_diff(small.flow, dense_flow(other.frame0, other.frame1, params).flow),
                0.0);
      EXPECT_EQ(test::max_abs_diff(lk.calc(s.frame0, s.frame1, options).flow, expected.flow), 0.0);
      // On pyramids built by the caller.
      const int levels = flow_pyramid_levels(s.frame0.size(), params, options);
      const Pyramid p0 = build_pyramid(s.frame0, levels, params.sigma);
      const Pyramid p1 = build_pyramid(s.frame1, levels, params.sigma);
      EXPECT_EQ(test::max_abs_diff(lk.calc(p0, p1, options).flow, expected.flow), 0.0);
    }
  }
}

TEST(DenseLkObjectTest, WithoutConfidenceTheFlowIsTheSameAndNoConfidenceIsLeft) {
  const Scene s = make_scene(SceneKind::NonRigid, kObjectSceneSize, 5);
  LkParams fast = LkParams::fast();
  fast.levels = 3;
  std::vector<LkParams> sets = parameter_sets();
  sets.push_back(fast);
  // The whole frame (the last iteration writes the result), a region, and LK stopping at
  // level 1 (the flow upsampled): each way the result is made.
  std::vector<FlowOptions> ways(3);
  ways[1].region = cv::Rect(20, 10, 90, 70);
  ways[2].finest_level = 1;
  for (const LkParams& params : sets) {
    DenseLK lk(params);
    for (const FlowOptions& way : ways) {
      FlowResult with, without;
      lk.calc(s.frame0, s.frame1, with, way);
      ASSERT_FALSE(with.confidence.empty());
      EXPECT_EQ(with.confidence.size(), with.flow.size());
      FlowOptions off = way;
      off.confidence = false;
      without.confidence = cv::Mat(4, 4, CV_32F, cv::Scalar(1));  // left over from a call before
      lk.calc(s.frame0, s.frame1, without, off);
      EXPECT_EQ(test::max_abs_diff(without.flow, with.flow), 0.0) << way.region << way.finest_level;
      EXPECT_TRUE(without.confidence.empty());
      EXPECT_EQ(without.region, with.region);
    }
  }
}

TEST(DenseLkObjectTest, CollectGarbageFreesTheWorkspaceAndTheNextCallRebuildsIt) {
  const Scene s = make_scene(SceneKind::Rotation, kObjectSceneSize, 5);
  DenseLK lk(LkParams::paper());
  EXPECT_EQ(lk.workspace_bytes(), 0u);
  const FlowResult first = lk.calc(s.frame0, s.frame1);
  // At least the two pyramids' level 0 and the four flow planes of level 0.
  const std::size_t least = (2 + 4) * kObjectSceneSize.area() * sizeof(float);
  EXPECT_GE(lk.workspace_bytes(), least);
  const std::size_t held = lk.workspace_bytes();
  lk.calc(s.frame0, s.frame1);
  EXPECT_EQ(lk.workspace_bytes(), held);  // reused, not grown
  lk.collectGarbage();
  EXPECT_EQ(lk.workspace_bytes(), 0u);
  EXPECT_EQ(test::max_abs_diff(lk.calc(s.frame0, s.frame1).flow, first.flow), 0.0);
  EXPECT_EQ(lk.workspace_bytes(), held);
  // reserve() takes what a pair of that size takes, and the pair then takes nothing more.
  DenseLK reserved(LkParams::paper());
  reserved.reserve(kObjectSceneSize);
  EXPECT_EQ(reserved.workspace_bytes(), held);
  EXPECT_EQ(test::max_abs_diff(reserved.calc(s.frame0, s.frame1).flow, first.flow), 0.0);
  EXPECT_EQ(reserved.workspace_bytes(), held);
  // A moved-from object holds nothing; the moved-to one goes on.
  DenseLK moved = std::move(lk);
  EXPECT_EQ(moved.workspace_bytes(), held);
  EXPECT_EQ(test::max_abs_diff(moved.calc(s.frame0, s.frame1).flow, first.flow), 0.0);
}

TEST(DenseLkObjectTest, BadParametersThrowInTheConstructorAndSetParams) {
  LkParams bad = LkParams::paper();
  bad.patch = 2;
  EXPECT_NE(error_message([&] { DenseLK lk(bad); }).find("patch"), std::string::npos);
  DenseLK lk;
  EXPECT_NE(error_message([&] { lk.set_params(bad); }).find("patch"), std::string::npos);
  EXPECT_EQ(lk.params().patch, LkParams::paper().patch);  // unchanged by the failed set
  lk.set_params(LkParams::accurate());
  EXPECT_EQ(lk.params().levels, LkParams::accurate().levels);
}

// ---------------------------------------------------------------------------------------------
// Every instruction set this CPU runs gives the same flow, up to the rounding of the vector
// width (prefix sums are added in a different order; AVX-512 sums the 8- and 10-wide windows
// directly) and of the reciprocal estimates. Widths that end inside a vector (200 = 12 * 16 + 8,
// 83 = 5 * 16 + 3) check that the lanes past a row's end stay out of its last windows.

TEST(LkKernelsTest, EveryInstructionSetAgreesWithTheBest) {
  const detail::LkKernels* kinds[8];
  const int n = detail::available_lk_kernels(kinds, 8);
  ASSERT_GE(n, 1);
  for (const cv::Size size : {cv::Size(200, 150), cv::Size(83, 61)}) {
    const Scene s = make_scene(SceneKind::MovingObject, size, 14);
    for (const LkParams& params : parameter_sets()) {
      detail::set_lk_kernels_for_testing(kinds[0]);
      const FlowResult best = dense_flow(s.frame0, s.frame1, params);
      for (int i = 1; i < n; ++i) {
        detail::set_lk_kernels_for_testing(kinds[i]);
        const FlowResult other = dense_flow(s.frame0, s.frame1, params);
        // (The measured gaps: docs/PERFORMANCE.md, "flow10's step".)
        EXPECT_LT(test::max_abs_diff(other.flow, best.flow), 1e-3)
            << kinds[i]->name << " " << size << " patch " << params.patch;
        EXPECT_LT(cv::mean(cv::abs(other.flow - best.flow))[0], 1e-5)
            << kinds[i]->name << " " << size << " patch " << params.patch;
      }
    }
  }
  detail::set_lk_kernels_for_testing(nullptr);
}

// ---------------------------------------------------------------------------------------------
// Through cv::DenseOpticalFlow, as an OpenCV user swaps it for DIS.

TEST(CreateDenseLkTest, GrayAndBgrThroughTheOpenCvInterfaceEqualDenseFlow) {
  const Scene gray = make_scene(SceneKind::Translation, kObjectSceneSize, 7);
  const Scene colour = colour_scene();
  for (const LkParams& params : parameter_sets()) {
    const cv::Ptr<cv::DenseOpticalFlow> of = createDenseLK(params);
    for (const Scene* s : {&gray, &colour}) {
      const cv::Mat expected = dense_flow(s->frame0, s->frame1, params).flow;
      cv::Mat flow;
      of->calc(s->frame0, s->frame1, flow);
      EXPECT_EQ(flow.type(), CV_32FC2);
      EXPECT_EQ(test::max_abs_diff(flow, expected), 0.0) << s->frame0.channels();
    }
  }
  // The colour pair's flow is as good as a gray pair's.
  cv::Mat flow;
  createDenseLK()->calc(colour.frame0, colour.frame1, flow);
  const cv::Rect inner(16, 16, kObjectSceneSize.width - 32, kObjectSceneSize.height - 32);
  EXPECT_LT(flow_errors(flow(inner), colour.flow(inner)).epe, 0.125);  // measured 0.104 px
}

TEST(CreateDenseLkTest, InputArrayVariantsAndOutputBuffers) {
  const Scene s = make_scene(SceneKind::Zoom, kObjectSceneSize, 8);
  const cv::Mat expected = dense_flow(s.frame0, s.frame1, LkParams::paper()).flow;
  const cv::Ptr<cv::DenseOpticalFlow> of = createDenseLK();

  // A preallocated flow of the right size and type is written in place.
  cv::Mat flow(kObjectSceneSize, CV_32FC2, cv::Scalar::all(7));
  const uchar* buffer = flow.data;
  of->calc(s.frame0, s.frame1, flow);
  EXPECT_EQ(flow.data, buffer);
  EXPECT_EQ(test::max_abs_diff(flow, expected), 0.0);
  // One of the wrong size or type is replaced.
  cv::Mat wrong(10, 10, CV_8UC1);
  of->calc(s.frame0, s.frame1, wrong);
  EXPECT_EQ(test::max_abs_diff(wrong, expected), 0.0);

  // cv::Mat_ inputs, UMat inputs and a UMat output.
  const cv::Mat1b a = s.frame0, b = s.frame1;
  cv::Mat typed;
  of->calc(a, b, typed);
  EXPECT_EQ(test::max_abs_diff(typed, expected), 0.0);
  cv::UMat ua, ub, uflow;
  s.frame0.copyTo(ua);
  s.frame1.copyTo(ub);
  of->calc(ua, ub, uflow);
  EXPECT_EQ(test::max_abs_diff(uflow.getMat(cv::ACCESS_READ), expected), 0.0);
  // A submatrix (not continuous) as input.
  cv::Mat wide0(kObjectSceneSize.height, kObjectSceneSize.width + 8, CV_8UC1, cv::Scalar(0));
  cv::Mat wide1 = wide0.clone();
  s.frame0.copyTo(wide0(cv::Rect(cv::Point(4, 0), kObjectSceneSize)));
  s.frame1.copyTo(wide1(cv::Rect(cv::Point(4, 0), kObjectSceneSize)));
  cv::Mat from_views;
  of->calc(wide0(cv::Rect(cv::Point(4, 0), kObjectSceneSize)),
           wide1(cv::Rect(cv::Point(4, 0), kObjectSceneSize)), from_views);
  EXPECT_EQ(test::max_abs_diff(from_views, expected), 0.0);

  // collectGarbage through the interface, then the same again.
  of->collectGarbage();
  cv::Mat again;
  of->calc(s.frame0, s.frame1, again);
  EXPECT_EQ(test::max_abs_diff(again, expected), 0.0);
}

TEST(CreateDenseLkTest, BadInputThrowsRoiflowError) {
  const cv::Ptr<cv::DenseOpticalFlow> of = createDenseLK();
  cv::Mat flow;
  const cv::Mat a(40, 30, CV_8UC1, cv::Scalar(1)), b(30, 40, CV_8UC1, cv::Scalar(1));
  EXPECT_NE(error_message([&] { of->calc(a, b, flow); }).find("30x40"), std::string::npos);
  EXPECT_THROW(of->calc(cv::Mat(), a, flow), Error);
  LkParams bad = LkParams::paper();
  bad.iterations = 0;
  EXPECT_THROW(createDenseLK(bad), Error);
}

// ---------------------------------------------------------------------------------------------
// FlowOptions::initial_flow.

TEST(InitialFlowTest, AUniformFieldEqualsTheInitialMotion) {
  const Scene s = make_scene(SceneKind::Translation, kObjectSceneSize, 9);
  const LkParams params = LkParams::paper();
  FlowOptions motion;
  motion.initial_motion = {2.f, -1.f};
  const int top = flow_pyramid_levels(kObjectSceneSize, params, motion) - 1;
  FlowOptions field;
  field.initial_flow = cv::Mat(level_size(kObjectSceneSize, top), CV_32FC2,
                               cv::Scalar(2.f / (1 << top), -1.f / (1 << top)));
  EXPECT_EQ(test::max_abs_diff(dense_flow(s.frame0, s.frame1, params, field).flow,
                               dense_flow(s.frame0, s.frame1, params, motion).flow),
            0.0);
  // Also for a region: the field is read over the region's rectangle of the coarsest level.
  motion.region = field.region = cv::Rect(40, 30, 60, 40);
  EXPECT_EQ(test::max_abs_diff(dense_flow(s.frame0, s.frame1, params, field).flow,
                               dense_flow(s.frame0, s.frame1, params, motion).flow),
            0.0);
}

TEST(InitialFlowTest, AFieldReachesMotionsBeyondThePyramid) {
  // Two objects moving 20 px apart: no single initial motion serves both, the field does.
  const cv::Size size(192, 96);
  const Scene left = make_translation(size, {20.f, 0.f}, 10);
  const Scene right = make_translation(size, {-20.f, 0.f}, 11);
  Scene s;
  const cv::Rect half(0, 0, size.width / 2, size.height);
  const cv::Rect other(size.width / 2, 0, size.width / 2, size.height);
  s.frame0 = left.frame0.clone();
  s.frame1 = left.frame1.clone();
  s.flow = left.flow.clone();
  right.frame0(other).copyTo(s.frame0(other));
  right.frame1(other).copyTo(s.frame1(other));
  right.flow(other).copyTo(s.flow(other));
  LkParams params = LkParams::paper();
  params.levels = 2;
  const int top = flow_pyramid_levels(size, params, {}) - 1;
  const cv::Size coarse = level_size(size, top);
  FlowOptions options;
  options.initial_flow = cv::Mat(coarse, CV_32FC2, cv::Scalar(20.f / (1 << top), 0.f));
  options
      .initial_flow(cv::Rect(coarse.width / 2, 0, coarse.width - coarse.width / 2, coarse.height))
      .setTo(cv::Scalar(-20.f / (1 << top), 0.f));
  // Counted inside each half, away from the seam and the borders where content leaves the frame.
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(28, 16, 24, 64)).setTo(0);
  mask(cv::Rect(140, 16, 24, 64)).setTo(0);
  const double seeded =
      flow_errors(dense_flow(s.frame0, s.frame1, params, options).flow, s.flow, mask).epe;
  const double plain = flow_errors(dense_flow(s.frame0, s.frame1, params).flow, s.flow, mask).epe;
  EXPECT_LT(seeded, 0.001);  // measured 3.3e-5 px
  EXPECT_GT(plain, 4.0);     // measured 5.61 px
}

TEST(InitialFlowTest, WrongSizeOrTypeNamesTheExpectedSize) {
  const Scene s = make_scene(SceneKind::Translation, kObjectSceneSize, 12);
  const LkParams params = LkParams::paper();  // 3 levels: the coarsest is 40x30
  FlowOptions options;
  options.initial_flow = cv::Mat(31, 40, CV_32FC2, cv::Scalar::all(0));
  std::string msg = error_message([&] { dense_flow(s.frame0, s.frame1, params, options); });
  EXPECT_NE(msg.find("40x30"), std::string::npos) << msg;
  EXPECT_NE(msg.find("40x31"), std::string::npos) << msg;
  options.initial_flow = cv::Mat(30, 40, CV_64FC2, cv::Scalar::all(0));
  msg = error_message([&] { dense_flow(s.frame0, s.frame1, params, options); });
  EXPECT_NE(msg.find("CV_64FC2"), std::string::npos) << msg;
}

}  // namespace
}  // namespace roiflow::flow
