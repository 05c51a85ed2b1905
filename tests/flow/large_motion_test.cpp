// Large displacements (flow/large_motion.hpp): the level count, the coarse search with its
// reliability checks and fill, the candidate fusion, the out-of-frame mask, and dense_flow
// with them on motions far beyond a patch.
#include "flow/large_motion.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "test_util.hpp"

namespace roiflow::flow {
namespace {

using test::error_message;

// A smooth random texture in [0, 1] (CV_32FC1).
cv::Mat texture(cv::Size size, std::uint64_t seed, double blur = 1.5) {
  cv::Mat noise(size, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.f, 1.f);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(), blur);
  return smooth;
}

// `image` moved by (dx, dy): out(x) = image(x - d), so the flow from image to out is d.
cv::Mat moved(const cv::Mat& image, cv::Point2f d) {
  cv::Mat out;
  const cv::Matx23d shift(1, 0, d.x, 0, 1, d.y);
  cv::warpAffine(image, out, shift, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

cv::Mat to8u(const cv::Mat& f) {
  cv::Mat out;
  f.convertTo(out, CV_8U, 255.0);
  return out;
}

// Share of the pixels of `rect` where (u, v) equals (du, dv) exactly.
double share_exact(const cv::Mat& u, const cv::Mat& v, const cv::Rect& rect, float du, float dv) {
  int hits = 0;
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    for (int x = rect.x; x < rect.x + rect.width; ++x)
      hits += u.at<float>(y, x) == du && v.at<float>(y, x) == dv;
  return static_cast<double>(hits) / rect.area();
}

TEST(AutoLevelsTest, CoarsestLevelKeepsFortyPixelsOrSeesASmallMotionAsTwo) {
  // Shorter sides 375 -> 188 -> 94 -> 47 (-> 24 is too small): levels 0..3.
  EXPECT_EQ(auto_levels({1242, 375}, 0.0), 4);
  EXPECT_EQ(auto_levels({640, 480}, 0.0), 4);   // 480 -> 60 at level 3, 30 at level 4
  EXPECT_EQ(auto_levels({1280, 720}, 0.0), 5);  // 720 -> 45 at level 4
  EXPECT_EQ(auto_levels({96, 64}, 0.0), 1);     // 64 -> 32 at level 1: no coarser level
  EXPECT_EQ(auto_levels({4000, 4000}, 0.0), kMaxLevels);
  // A 3 px motion is 1.5 px at level 1: two levels are enough; 20 px needs four (2.5 -> 1.25).
  EXPECT_EQ(auto_levels({640, 480}, 3.0), 2);
  EXPECT_EQ(auto_levels({640, 480}, 20.0), 4);
  EXPECT_NE(error_message([] { auto_levels({0, 10}, 0.0); }).find("empty"), std::string::npos);

  LkParams params = LkParams::paper();
  params.levels = 0;
  EXPECT_EQ(flow_pyramid_levels({1242, 375}, params, {}), 4);
  params.expected_motion = 3.0;
  EXPECT_EQ(flow_pyramid_levels({1242, 375}, params, {}), 2);
}

TEST(AutoLevelsTest, SearchRadiusCoversTheExpectedMotionUpToItsCap) {
  // A quarter of 640 is 160 px, 20 px at level 3: capped at 12.
  EXPECT_EQ(search_radius_for({640, 480}, 3, 0.0, 12), 12);
  EXPECT_EQ(search_radius_for({640, 480}, 3, 40.0, 12), 5);
  EXPECT_EQ(search_radius_for({640, 480}, 4, 0.0, 12), 10);
  EXPECT_EQ(search_radius_for({640, 480}, 3, 0.5, 12), 1);
}

TEST(CoarseSearchTest, FindsATranslationFarBeyondThePatch) {
  const cv::Mat i0 = texture({64, 48}, 1);
  const cv::Mat i1 = moved(i0, {7.f, -5.f});
  cv::Mat u(i0.size(), CV_32F, 0.f), v(i0.size(), CV_32F, 0.f);
  search_flow(i0, i1, {0.f, 0.f}, SearchParams{}, u, v);
  // Away from the borders that the motion uncovers, every pixel finds it (measured: all).
  EXPECT_EQ(share_exact(u, v, {4, 9, 49, 35}, 7.f, -5.f), 1.0);
}

TEST(CoarseSearchTest, SearchesAroundThePrior) {
  const cv::Mat i0 = texture({64, 48}, 2);
  const cv::Mat i1 = moved(i0, {14.f, 2.f});
  SearchParams params;
  params.radius = 3;  // 14 px is out of reach from zero, not from a prior of (12.4, 0.6)
  cv::Mat u(i0.size(), CV_32F, 0.f), v(i0.size(), CV_32F, 0.f);
  search_flow(i0, i1, {12.4f, 0.6f}, params, u, v);
  EXPECT_EQ(share_exact(u, v, {4, 6, 40, 36}, 14.f, 2.f), 1.0);
}

TEST(CoarseSearchTest, FlatFramesKeepThePrior) {
  // Any displacement fits a flat window as well as the prior: nothing beats it by the margin.
  const cv::Mat flat(30, 40, CV_32F, cv::Scalar(0.4));
  cv::Mat u(flat.size(), CV_32F, 0.f), v(flat.size(), CV_32F, 0.f);
  search_flow(flat, flat, {2.f, -1.f}, SearchParams{}, u, v);
  EXPECT_EQ(share_exact(u, v, {0, 0, 40, 30}, 2.f, -1.f), 1.0);
}

TEST(CoarseSearchTest, AMovingObjectAndItsStaticBackgroundEachGetTheirMotion) {
  // Background still; a textured 24x24 square moves by (9, 3). Occluded and uncovered pixels
  // fail the forward-backward check and are filled; the insides of both are exact.
  const cv::Mat background = texture({96, 72}, 3);
  const cv::Mat object = texture({24, 24}, 4);
  cv::Mat i0 = background.clone(), i1 = background.clone();
  object.copyTo(i0(cv::Rect(30, 20, 24, 24)));
  object.copyTo(i1(cv::Rect(39, 23, 24, 24)));
  cv::Mat u(i0.size(), CV_32F, 0.f), v(i0.size(), CV_32F, 0.f);
  search_flow(i0, i1, {0.f, 0.f}, SearchParams{}, u, v);
  EXPECT_EQ(share_exact(u, v, {34, 24, 16, 16}, 9.f, 3.f), 1.0);  // the object's inside
  EXPECT_EQ(share_exact(u, v, {4, 50, 88, 18}, 0.f, 0.f), 1.0);   // background below it
  EXPECT_EQ(share_exact(u, v, {70, 4, 22, 40}, 0.f, 0.f), 1.0);   // and to its right
}

TEST(CoarseSearchTest, RejectsBadInput) {
  const cv::Mat image(20, 20, CV_32F, cv::Scalar(0.5));
  cv::Mat u(image.size(), CV_32F, 0.f), v(image.size(), CV_32F, 0.f);
  SearchParams bad;
  bad.radius = kMaxSearchRadius + 1;
  EXPECT_NE(error_message([&] { search_flow(image, image, {}, bad, u, v); }).find("radius 25"),
            std::string::npos);
  bad = SearchParams{};
  bad.window = 8;
  EXPECT_NE(error_message([&] { search_flow(image, image, {}, bad, u, v); }).find("window 8"),
            std::string::npos);
  cv::Mat small(10, 10, CV_32F, 0.f);
  EXPECT_NE(error_message([&] {
              search_flow(image, image, {}, SearchParams{}, small, v);
            }).find("one size"),
            std::string::npos);
  EXPECT_THROW(fuse_candidates(image, image, 0, 7, u, v), Error);
  EXPECT_THROW(fuse_candidates(image, image, 4, 6, u, v), Error);
  EXPECT_THROW(fuse_candidates(image, cv::Mat(), 4, 7, u, v), Error);
}

TEST(CandidateFusionTest, AWrongBandTakesItsNeighboursFlow) {
  const cv::Mat i0 = texture({80, 60}, 5);
  const cv::Mat i1 = moved(i0, {2.5f, -1.25f});
  cv::Mat u(i0.size(), CV_32F, 2.5f), v(i0.size(), CV_32F, -1.25f);
  // A band 3 pixels wide lost the motion (as a coarse level can blur it away).
  u.colRange(38, 41).setTo(0.f);
  v.colRange(38, 41).setTo(0.f);
  fuse_candidates(i0, i1, 4, 7, u, v);
  EXPECT_EQ(share_exact(u, v, {6, 6, 68, 48}, 2.5f, -1.25f), 1.0);
}

// An executor that claims two threads and runs the chunks one by one, the last first: the
// threaded schedule of fuse_candidates, in an order no serial loop would take.
class ReversedChunks final : public Executor {
 public:
  void for_range(int begin, int end, int grain,
                 const std::function<void(int, int)>& body) const override {
    std::vector<std::pair<int, int>> chunks = test::chunks_of(begin, end, grain);
    for (auto it = chunks.rbegin(); it != chunks.rend(); ++it)
      it->first < it->second ? body(it->first, it->second) : void();
    calls += static_cast<int>(chunks.size());
  }
  int concurrency() const override { return 2; }
  mutable int calls = 0;
};

TEST(CandidateFusionTest, ThreadedScheduleGivesTheSerialResultBitForBit) {
  const cv::Mat i0 = texture({83, 61}, 8);
  const cv::Mat i1 = moved(i0, {1.75f, 2.5f});
  // A start with several motions, so that every candidate direction wins somewhere.
  const cv::Mat u0 = texture({83, 61}, 9) * 6.f, v0 = texture({83, 61}, 10) * -5.f;
  std::vector<float> scratch;  // kept across the calls, as DenseLK keeps it
  for (const int step : {1, 4, 16}) {
    cv::Mat u = u0.clone(), v = v0.clone();
    fuse_candidates(i0, i1, step, 7, u, v);
    EXPECT_GT(cv::norm(u, u0, cv::NORM_INF), 0.0) << "step " << step;
    for (const bool own_scratch : {false, true}) {
      cv::Mat tu = u0.clone(), tv = v0.clone();
      const ReversedChunks two;
      fuse_candidates(i0, i1, step, 7, tu, tv, &two, own_scratch ? nullptr : &scratch);
      EXPECT_GT(two.calls, 9) << "step " << step;
      EXPECT_EQ(cv::norm(u, tu, cv::NORM_INF), 0.0) << "step " << step;
      EXPECT_EQ(cv::norm(v, tv, cv::NORM_INF), 0.0) << "step " << step;
    }
  }
}

TEST(CoarseSearchTest, ThreadedScheduleGivesTheSerialResultBitForBit) {
  const cv::Mat i0 = texture({71, 53}, 11);
  const cv::Mat i1 = moved(i0, {6.f, -4.f});
  for (const int radius : {3, 8}) {
    SearchParams params;
    params.radius = radius;
    cv::Mat u(i0.size(), CV_32F, 0.f), v(i0.size(), CV_32F, 0.f);
    search_flow(i0, i1, {0.5f, 0.f}, params, u, v);
    cv::Mat tu(i0.size(), CV_32F, 0.f), tv(i0.size(), CV_32F, 0.f);
    const ReversedChunks two;
    search_flow(i0, i1, {0.5f, 0.f}, params, tu, tv, &two);
    EXPECT_GT(two.calls, 2) << "radius " << radius;
    EXPECT_GT(cv::countNonZero(u != 0.f), 0) << "radius " << radius;
    EXPECT_EQ(cv::norm(u, tu, cv::NORM_INF), 0.0) << "radius " << radius;
    EXPECT_EQ(cv::norm(v, tv, cv::NORM_INF), 0.0) << "radius " << radius;
  }
}

TEST(CandidateFusionTest, FlatFramesKeepEveryPixelsOwnFlow) {
  // Every candidate ties on flat frames: each pixel keeps its own flow, bit for bit.
  const cv::Mat flat(30, 40, CV_32F, cv::Scalar(0.25));
  const cv::Mat u0 = texture({40, 30}, 6) * 4.f, v0 = texture({40, 30}, 7) * -3.f;
  cv::Mat u = u0.clone(), v = v0.clone();
  fuse_candidates(flat, flat, 5, 7, u, v);
  EXPECT_EQ(cv::norm(u, u0, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(v, v0, cv::NORM_INF), 0.0);
}

// A pixel whose sample of frame t+1 leaves the frame has no brightness term: with
// mask_outside it keeps the flow it came with instead of being pulled to the replicated border.
TEST(MaskOutsideTest, PixelsLeavingTheFrameKeepTheirFlow) {
  const cv::Mat i0 = texture({160, 120}, 13, 2.0);
  const cv::Point2f motion(6.f, 0.f);
  const cv::Mat frame0 = to8u(i0), frame1 = to8u(moved(i0, motion));
  LkParams params = LkParams::paper();
  params.iterations = 8;
  FlowOptions options;
  options.initial_motion = motion;  // the right answer from the start
  const cv::Mat truth(i0.size(), CV_32FC2, cv::Scalar(motion.x, motion.y));
  cv::Mat not_edge(i0.size(), CV_8UC1, cv::Scalar(0));  // the last 6 columns leave the frame
  not_edge(cv::Rect(0, 0, 154, 120)).setTo(255);
  const FlowErrors pulled =
      flow_errors(dense_flow(frame0, frame1, params, options).flow, truth, not_edge);
  params.mask_outside = true;
  const FlowErrors kept =
      flow_errors(dense_flow(frame0, frame1, params, options).flow, truth, not_edge);
  // Measured: 4.21 px pulled, 0.003 px kept.
  EXPECT_GT(pulled.epe, 2.0);
  EXPECT_LT(kept.epe, 0.01);
}

// dense_flow end to end: a 40 px translation of a 320x240 texture is ten patches away. The
// paper's 3 levels see it as 10 px at their coarsest level and lose it; the search finds it.
TEST(LargeMotionTest, PresetsWithTheSearchFollowAFortyPixelTranslation) {
  const cv::Mat i0 = texture({320, 240}, 10, 2.0);
  const cv::Point2f motion(40.f, -12.f);
  const cv::Mat frame0 = to8u(i0), frame1 = to8u(moved(i0, motion));
  const cv::Mat truth(i0.size(), CV_32FC2, cv::Scalar(motion.x, motion.y));
  cv::Mat inside(i0.size(), CV_8UC1, cv::Scalar(255));  // pixels still in view, away from edges
  inside(cv::Rect(8, 20, 260, 212)).setTo(0);
  const FlowErrors paper =
      flow_errors(dense_flow(frame0, frame1, LkParams::paper()).flow, truth, inside);
  EXPECT_GT(paper.epe, 10.0);  // measured 42.4 px
  // Measured: accurate < 1e-4 px, fast 0.100 px (LK stops at level 2 and is upsampled x4).
  const std::pair<const char*, double> presets[] = {{"accurate", 0.005}, {"fast", 0.15}};
  for (const auto& [name, bound] : presets) {
    const FlowResult r = dense_flow(frame0, frame1, LkParams::preset(name));
    ASSERT_EQ(r.flow.size(), i0.size());
    EXPECT_LT(flow_errors(r.flow, truth, inside).epe, bound) << name;
  }
}

TEST(LargeMotionTest, AGivenInitialFlowReplacesTheSearch) {
  // The search would find the motion; a start from the caller is taken as it is instead.
  const cv::Mat i0 = texture({320, 240}, 11, 2.0);
  const cv::Mat frame0 = to8u(i0), frame1 = to8u(moved(i0, {40.f, 0.f}));
  LkParams params = LkParams::accurate();
  params.fuse_step = 0;
  const int top = flow_pyramid_levels(i0.size(), params, {}) - 1;
  FlowOptions options;
  options.initial_flow = cv::Mat(level_size(i0.size(), top), CV_32FC2, cv::Scalar(-3.f, 0.f));
  const FlowResult r = dense_flow(frame0, frame1, params, options);
  // Started 43 px off, LK alone cannot get there (measured mean u -11.7 px); the search does
  // (39.9: the strip that leaves the view is not 40 everywhere).
  EXPECT_LT(cv::mean(r.flow)[0], 20.0);
  EXPECT_GT(cv::mean(dense_flow(frame0, frame1, params).flow)[0], 39.0);
}

TEST(LargeMotionTest, RegionsAreSearchedWithinThemselves) {
  const cv::Mat i0 = texture({320, 240}, 12, 2.0);
  const cv::Point2f motion(24.f, 8.f);
  const cv::Mat frame0 = to8u(i0), frame1 = to8u(moved(i0, motion));
  FlowOptions options;
  options.region = cv::Rect(80, 60, 160, 120);
  const FlowResult r = dense_flow(frame0, frame1, LkParams::accurate(), options);
  ASSERT_EQ(r.flow.size(), options.region.size());
  const cv::Mat truth(r.flow.size(), CV_32FC2, cv::Scalar(motion.x, motion.y));
  cv::Mat edge(r.flow.size(), CV_8UC1, cv::Scalar(255));
  edge(cv::Rect(16, 16, 128, 88)).setTo(0);
  EXPECT_LT(flow_errors(r.flow, truth, edge).epe, 0.005);  // measured < 1e-4 px
}

}  // namespace
}  // namespace roiflow::flow
