// Dense LK against synthetic scenes with exact ground truth (eval/synthetic.hpp).
#include "flow/dense_lk.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/synthetic.hpp"
#include "flow/metrics.hpp"
#include "test_util.hpp"

// Every accuracy bar below is the value measured on the implementation of this commit (Release,
// x86-64 with AVX2; "measured" comments) plus about 20 %: a real regression of 30 % fails, the
// ~1e-4 px that a reordering of float operations may move does not.

namespace roiflow::flow {
namespace {

using eval::make_scene;
using eval::make_translation;
using eval::Scene;
using eval::SceneKind;

const cv::Size kSize(320, 240);
// LK windows are clipped at the image border and content enters or leaves there: that band
// is legitimately worse and is left out of every accuracy figure.
constexpr int kBorder = 16;

cv::Mat border_mask(cv::Size size, int border) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(border, border, size.width - 2 * border, size.height - 2 * border)).setTo(0);
  return mask;
}

FlowErrors interior_errors(const cv::Mat& flow, const cv::Mat& truth, int border = kBorder) {
  return flow_errors(flow, truth, border_mask(flow.size(), border));
}

bool all_finite(const cv::Mat& m) {
  return cv::checkRange(m, true, nullptr, -1e30, 1e30);
}

double masked_median(const cv::Mat& channel, const cv::Mat& mask) {
  std::vector<float> values;
  for (int y = 0; y < channel.rows; ++y) {
    for (int x = 0; x < channel.cols; ++x) {
      if (mask.at<uchar>(y, x)) values.push_back(channel.at<float>(y, x));
    }
  }
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// A flow field resampled at x + shift (bilinear).
cv::Mat shifted(const cv::Mat& flow, cv::Point2f shift) {
  cv::Mat map(flow.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x)
      map.at<cv::Vec2f>(y, x) = cv::Vec2f(x + shift.x, y + shift.y);
  }
  cv::Mat out;
  cv::remap(flow, out, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

LkParams with_patch(LkParams p, int patch) {
  p.patch = patch;
  return p;
}

LkParams with_derivative(LkParams p, Derivative d) {
  p.derivative = d;
  return p;
}

using test::error_message;

// Parameter sets for the properties that must hold for every setting: both presets (the
// accurate one adds robust weights and medians), an even and an odd patch, both derivative
// grids.
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

// ---------------------------------------------------------------------------------------------
// Accuracy on synthetic scenes with exact ground truth.

struct AccuracyCase {
  SceneKind kind;
  const char* preset;
  double max_epe;  // px
  double max_aae;  // degrees
};

class DenseLkAccuracyTest : public testing::TestWithParam<AccuracyCase> {};

TEST_P(DenseLkAccuracyTest, MeanErrorsBelowBar) {
  const AccuracyCase& c = GetParam();
  const Scene s = make_scene(c.kind, kSize, 7);
  const FlowResult r = dense_flow(s.frame0, s.frame1, LkParams::preset(c.preset));
  ASSERT_EQ(r.flow.size(), kSize);
  ASSERT_EQ(r.flow.type(), CV_32FC2);
  ASSERT_EQ(r.region, cv::Rect(cv::Point(), kSize));
  const FlowErrors e = interior_errors(r.flow, s.flow);
  EXPECT_EQ(e.pixels, (kSize.width - 2 * kBorder) * (kSize.height - 2 * kBorder));
  EXPECT_LT(e.epe, c.max_epe) << to_string(c.kind) << " / " << c.preset;
  EXPECT_LT(e.aae_deg, c.max_aae) << to_string(c.kind) << " / " << c.preset;
}

INSTANTIATE_TEST_SUITE_P(
    DenseLkTest, DenseLkAccuracyTest,
    testing::Values(
        // Bars: EPE px, AAE deg. Comments: the measured EPE / AAE.
        AccuracyCase{SceneKind::Translation, "paper", 0.030, 0.78},      // 0.0248 / 0.649
        AccuracyCase{SceneKind::Rotation, "paper", 0.150, 1.49},         // 0.1247 / 1.242
        AccuracyCase{SceneKind::Zoom, "paper", 0.107, 1.36},             // 0.0891 / 1.131
        AccuracyCase{SceneKind::NonRigid, "paper", 0.188, 5.88},         // 0.1562 / 4.899
        AccuracyCase{SceneKind::MovingObject, "paper", 0.100, 2.62},     // 0.0835 / 2.186
        AccuracyCase{SceneKind::Translation, "accurate", 0.0294, 0.77},  // 0.0245 / 0.638
        AccuracyCase{SceneKind::Rotation, "accurate", 0.126, 1.25},      // 0.1052 / 1.043
        AccuracyCase{SceneKind::Zoom, "accurate", 0.083, 1.05},          // 0.0690 / 0.876
        AccuracyCase{SceneKind::NonRigid, "accurate", 0.157, 4.90},      // 0.1305 / 4.083
        AccuracyCase{SceneKind::MovingObject, "accurate", 0.072, 2.03},  // 0.0601 / 1.691
        // `fast` stops LK at level 2 (a quarter of the resolution) and upsamples: a
        // deformation finer than 4 pixels is lost (nonrigid).
        AccuracyCase{SceneKind::Translation, "fast", 0.124, 2.65},    // 0.1034 / 2.205
        AccuracyCase{SceneKind::Rotation, "fast", 0.463, 4.46},       // 0.3857 / 3.716
        AccuracyCase{SceneKind::Zoom, "fast", 0.361, 4.08},           // 0.3009 / 3.404
        AccuracyCase{SceneKind::NonRigid, "fast", 1.066, 35.3},       // 0.8883 / 29.42
        AccuracyCase{SceneKind::MovingObject, "fast", 0.237, 4.68}),  // 0.1972 / 3.902
    [](const testing::TestParamInfo<AccuracyCase>& param_info) {
      return std::string(to_string(param_info.param.kind)) + "_" + param_info.param.preset;
    });

TEST(DenseLkTest, MovingObjectInteriorFollowsTheObject) {
  const Scene s = make_scene(SceneKind::MovingObject, kSize, 7);
  const cv::Point2f object_motion(3.2f, 1.5f);  // synthetic.cpp's kObjectMotion
  cv::Mat object(kSize, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < kSize.height; ++y) {
    for (int x = 0; x < kSize.width; ++x) {
      const cv::Vec2f d = s.flow.at<cv::Vec2f>(y, x);
      if (std::abs(d[0] - object_motion.x) < 1e-4f && std::abs(d[1] - object_motion.y) < 1e-4f)
        object.at<uchar>(y, x) = 255;
    }
  }
  double epe[2];
  int i = 0;
  for (const char* preset : {"paper", "accurate"}) {
    const LkParams params = LkParams::preset(preset);
    // Windows straddling the boundary mix both motions: keep pixels a patch away from it.
    cv::Mat interior;
    cv::erode(object, interior,
              cv::getStructuringElement(cv::MORPH_RECT,
                                        cv::Size(2 * params.patch + 1, 2 * params.patch + 1)));
    ASSERT_GT(cv::countNonZero(interior), 1000) << preset;  // 60x40 of the 80x60 object
    const FlowResult r = dense_flow(s.frame0, s.frame1, params);
    cv::Mat uv[2];
    cv::split(r.flow, uv);
    // Measured deviations of the medians: paper (0.0097, 0.0016), accurate (0.0092, 0.0016).
    EXPECT_NEAR(masked_median(uv[0], interior), object_motion.x, 0.015) << preset;
    EXPECT_NEAR(masked_median(uv[1], interior), object_motion.y, 0.015) << preset;
    epe[i++] = interior_errors(r.flow, s.flow).epe;
  }
  // Robust weights and medians are what `accurate` adds for motion boundaries: measured
  // 0.0568 vs 0.0835 px, ratio 0.68.
  EXPECT_LT(epe[1], 0.8 * epe[0]);
}

// ---------------------------------------------------------------------------------------------
// Pyramid, patch sizes, derivatives.

TEST(DenseLkTest, PyramidRecoversLargeMotionSingleLevelDoesNot) {
  const Scene s = make_translation(kSize, {7.5f, -4.25f}, 11);
  LkParams params = LkParams::paper();
  params.levels = 3;
  const FlowErrors three = interior_errors(dense_flow(s.frame0, s.frame1, params).flow, s.flow);
  params.levels = 1;
  const FlowErrors one = interior_errors(dense_flow(s.frame0, s.frame1, params).flow, s.flow);
  EXPECT_LT(three.epe, 0.030);  // measured 0.0247 px
  // A 10 px window's linearisation reaches ~1-2 px: one level stays far off (measured 2.01 px
  // mean EPE). Documents why the pyramid is there.
  EXPECT_GT(one.epe, 1.0);
}

TEST(DenseLkTest, EvenAndOddPatchesConvergeOnTranslation) {
  struct Case {
    int patch;
    Derivative derivative;
    double max_epe;
  };
  const Case cases[] = {
      {9, Derivative::HornSchunck, 0.038},    // measured 0.0315
      {9, Derivative::Scharr, 0.043},         // 0.0358
      {10, Derivative::HornSchunck, 0.034},   // 0.0286
      {10, Derivative::Scharr, 0.035},        // 0.0294
      {11, Derivative::HornSchunck, 0.029},   // 0.0239
      {11, Derivative::Scharr, 0.032},        // 0.0269
      {4, Derivative::HornSchunck, 0.104},    // 0.0864
      {4, Derivative::Scharr, 0.096},         // 0.0799
      {31, Derivative::HornSchunck, 0.0065},  // 0.0054
      {31, Derivative::Scharr, 0.0070},       // 0.0059
  };
  const Scene s = make_scene(SceneKind::Translation, kSize, 5);
  for (const Case& c : cases) {
    const LkParams params = with_derivative(with_patch(LkParams::paper(), c.patch), c.derivative);
    const FlowResult r = dense_flow(s.frame0, s.frame1, params);
    const FlowErrors e = interior_errors(r.flow, s.flow, std::max(kBorder, c.patch + 2));
    EXPECT_LT(e.epe, c.max_epe) << "patch " << c.patch << " " << to_string(c.derivative);
  }
}

// An even patch has no centre pixel; the implementation centres it with half-weight ends (see
// dense_lk.hpp). A window sitting half a pixel off would estimate the flow at x + 1/2.
TEST(DenseLkTest, EvenPatchHasNoHalfPixelShift) {
  const Scene s = make_scene(SceneKind::NonRigid, kSize, 3);
  struct Case {
    Derivative derivative;
    double max_centred;  // px
  };
  for (const Case& c : {Case{Derivative::HornSchunck, 0.0165}, Case{Derivative::Scharr, 0.0095}}) {
    const LkParams params = with_derivative(LkParams::paper(), c.derivative);
    const cv::Mat flow9 = dense_flow(s.frame0, s.frame1, with_patch(params, 9)).flow;
    const cv::Mat flow10 = dense_flow(s.frame0, s.frame1, with_patch(params, 10)).flow;
    const cv::Mat flow11 = dense_flow(s.frame0, s.frame1, with_patch(params, 11)).flow;
    const double epe9 = interior_errors(flow9, s.flow).epe;
    const double epe10 = interior_errors(flow10, s.flow).epe;
    const double epe11 = interior_errors(flow11, s.flow).epe;
    // Measured hs 0.1467 / 0.1553 / 0.1624, scharr 0.1480 / 0.1537 / 0.1626 (a larger window
    // averages more of the field's curvature): patch 10 is their mean within 1 %.
    EXPECT_LT(epe10, 1.1 * 0.5 * (epe9 + epe11)) << to_string(c.derivative);

    // Neighbouring patch sizes share most of their error, so the odd patches' mean isolates a
    // shift: patch 10 must match it as is (measured hs 0.0137, scharr 0.0078 px), much better
    // than shifted by half a pixel along x or y (measured 0.039..0.041 and 0.037..0.039 px;
    // the field itself moves 0.030 px under such a shift).
    const cv::Mat odd_mean = 0.5 * (flow9 + flow11);
    const double centred = interior_errors(flow10, odd_mean).epe;
    EXPECT_LT(centred, c.max_centred) << to_string(c.derivative);
    for (const cv::Point2f shift : {cv::Point2f(0.5f, 0.f), cv::Point2f(-0.5f, 0.f),
                                    cv::Point2f(0.f, 0.5f), cv::Point2f(0.f, -0.5f)}) {
      const double off = interior_errors(flow10, shifted(odd_mean, shift)).epe;
      EXPECT_LT(centred, 0.5 * off) << to_string(c.derivative) << " shift " << shift;
    }
  }
}

TEST(DenseLkTest, AllDerivativesWork) {
  struct Case {
    Derivative derivative;
    double max_epe;
  };
  const Scene s = make_scene(SceneKind::Rotation, kSize, 9);
  for (const Case& c : {Case{Derivative::HornSchunck, 0.127},  // measured 0.1061 px
                        Case{Derivative::Scharr, 0.126},       // 0.1053
                        Case{Derivative::Central, 0.123}}) {   // 0.1023
    const LkParams params = with_derivative(LkParams::paper(), c.derivative);
    const FlowErrors e = interior_errors(dense_flow(s.frame0, s.frame1, params).flow, s.flow);
    EXPECT_LT(e.epe, c.max_epe) << to_string(c.derivative);
    EXPECT_LT(e.aae_deg, 1.22) << to_string(c.derivative);  // measured 0.98 .. 1.01 deg
  }
}

// ---------------------------------------------------------------------------------------------
// Region of interest.

// dense_lk.cpp computes each level on the region plus a margin wide enough for every
// iteration's window and stencil and the medians, so the region's flow is the whole frame's
// up to the rounding of the running window sums, which start at different rows and columns
// (measured: max 1.6e-3 px for paper, 1.4e-2 px for accurate, where ill-conditioned windows
// amplify it; the mean difference stays below 1e-4 px).
TEST(DenseLkTest, RegionEqualsWholeFrameFlowInsideIt) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 4);
  const cv::Rect full(cv::Point(), kSize);
  const cv::Rect regions[] = {
      {117, 83, 64, 48},   // interior
      {0, 0, 50, 40},      // top-left corner
      {270, 200, 50, 40},  // bottom-right corner
      {0, 100, 320, 7},    // a full-width band
      {160, 120, 1, 1},    // one pixel
      {-20, 210, 60, 80},  // partly outside: clipped to (0, 210, 40, 30)
  };
  for (const NamedParams& c : configurations()) {
    const FlowResult whole = dense_flow(s.frame0, s.frame1, c.params);
    for (const cv::Rect& region : regions) {
      FlowOptions options;
      options.region = region;
      const FlowResult part = dense_flow(s.frame0, s.frame1, c.params, options);
      const cv::Rect clipped = region & full;
      ASSERT_EQ(part.region, clipped) << c.name << " " << region;
      ASSERT_EQ(part.flow.size(), clipped.size()) << c.name << " " << region;
      ASSERT_EQ(part.flow.type(), CV_32FC2);
      ASSERT_EQ(part.confidence.size(), clipped.size()) << c.name << " " << region;
      EXPECT_LT(test::max_abs_diff(part.flow, whole.flow(clipped)), 0.03)
          << c.name << " " << region;
      cv::Mat diff;
      cv::absdiff(part.flow, whole.flow(clipped), diff);
      const cv::Scalar mean_diff = cv::mean(diff);
      EXPECT_LT(std::max(mean_diff[0], mean_diff[1]), 1e-3) << c.name << " " << region;
      EXPECT_LT(test::max_abs_diff(part.confidence, whole.confidence(clipped)), 1e-6)
          << c.name << " " << region;
    }
  }
}

TEST(DenseLkTest, ASmallerContextChangesTheFlowOnlyNearTheRegionBorder) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 4);
  const cv::Rect region(110, 80, 90, 70);
  FlowOptions exact;
  exact.region = region;
  const FlowResult reference = dense_flow(s.frame0, s.frame1, LkParams::paper(), exact);
  FlowOptions small = exact;
  small.context = 8;
  const FlowResult cheap = dense_flow(s.frame0, s.frame1, LkParams::paper(), small);
  ASSERT_EQ(cheap.flow.size(), region.size());
  // Away from the border (more than a window and the context), the two agree closely; at the
  // border they may not, which is why exact context stays the default.
  const cv::Rect inner(20, 20, region.width - 40, region.height - 40);
  EXPECT_LT(test::max_abs_diff(cheap.flow(inner), reference.flow(inner)), 0.05);
  EXPECT_GT(test::max_abs_diff(cheap.flow, reference.flow), 1e-4);  // the context was honoured
  EXPECT_LT(test::max_abs_diff(cheap.flow, s.flow(region)), 1.0);
  for (int bad : {-2, 1001}) {
    FlowOptions options = exact;
    options.context = bad;
    EXPECT_NE(error_message([&] {
                dense_flow(s.frame0, s.frame1, LkParams::paper(), options);
              }).find(std::to_string(bad)),
              std::string::npos);
  }
}

// The pyramids of only the footprint (plus a border for the smoothing and pyrDown, origin on
// the coarsest level's grid) give the flow the whole-frame pyramids give: what lets a tracker
// build pyramids of a small part of each frame.
TEST(DenseLkTest, PyramidsOfTheFootprintGiveTheRegionsFlow) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 4);
  for (int context : {8, -1}) {
    SCOPED_TRACE("context " + std::to_string(context));
    FlowOptions options;
    options.region = cv::Rect(110, 80, 90, 70);
    options.context = context;
    const LkParams params = LkParams::paper();
    const cv::Rect footprint = flow_footprint(s.frame0.size(), params, options);
    EXPECT_TRUE((footprint & options.region) == options.region);
    EXPECT_GT(footprint.area(), options.region.area());
    const FlowResult whole = dense_flow(s.frame0, s.frame1, params, options);
    const int align = 1 << (params.levels - 1);
    const int x0 = std::max(0, (footprint.x - 16) / align * align);
    const int y0 = std::max(0, (footprint.y - 16) / align * align);
    const cv::Rect crop = cv::Rect(cv::Point(x0, y0), footprint.br() + cv::Point(16, 16)) &
                          cv::Rect(cv::Point(), s.frame0.size());
    FlowOptions inside = options;
    inside.region = options.region - crop.tl();
    const FlowResult part = dense_flow(s.frame0(crop), s.frame1(crop), params, inside);
    EXPECT_LT(test::max_abs_diff(part.flow, whole.flow), 1e-3);
  }
}

// LK stopped at a coarser level: the flow of that level, upsampled, still follows a smooth
// motion to a fraction of a pixel at a quarter of the cost per level skipped, and the region's
// flow is the whole frame's there; its footprint is what the region's flow reads.
TEST(DenseLkTest, AFinestLevelAboveZeroGivesTheCoarserFlowUpsampled) {
  const Scene s = make_translation(kSize, {7.5f, -4.25f}, 11);
  const LkParams params = LkParams::paper();
  FlowOptions coarse;
  coarse.finest_level = 1;
  // Levels 1 and 2 of 3; from level 2 on, two levels (2, 3); one level asked, one given.
  EXPECT_EQ(flow_pyramid_levels(kSize, params, coarse), params.levels);
  EXPECT_EQ(flow_pyramid_levels(kSize, params, {}), params.levels);
  FlowOptions higher;
  higher.finest_level = 2;
  EXPECT_EQ(flow_pyramid_levels(kSize, params, higher), 4);
  LkParams one = params;
  one.levels = 1;
  EXPECT_EQ(flow_pyramid_levels(kSize, one, higher), 3);
  const FlowResult r = dense_flow(s.frame0, s.frame1, params, coarse);
  ASSERT_EQ(r.flow.size(), kSize);
  ASSERT_EQ(r.confidence.size(), kSize);
  const FlowErrors e = interior_errors(r.flow, s.flow);
  EXPECT_LT(e.epe, 0.05);  // measured 0.038 px (0.025 at level 0)
  // The same level-1 problem solved directly on the half-size frames, then doubled.
  const Pyramid p0 = build_pyramid(s.frame0, params.levels, params.sigma);
  const Pyramid p1 = build_pyramid(s.frame1, params.levels, params.sigma);
  Pyramid h0, h1;
  h0.levels.assign(p0.levels.begin() + 1, p0.levels.end());
  h1.levels.assign(p1.levels.begin() + 1, p1.levels.end());
  LkParams two = params;
  two.levels = params.levels - 1;
  const FlowResult half = dense_flow(h0, h1, two);
  const cv::Rect inner(40, 40, 80, 60);  // level-1 pixels, away from the border
  for (int y = inner.y; y < inner.y + inner.height; y += 7) {
    for (int x = inner.x; x < inner.x + inner.width; x += 7) {
      const cv::Vec2f want = 2.f * half.flow.at<cv::Vec2f>(y, x);
      const cv::Vec2f got = r.flow.at<cv::Vec2f>(2 * y, 2 * x);
      EXPECT_NEAR(got[0], want[0], 1e-4) << x << "," << y;
      EXPECT_NEAR(got[1], want[1], 1e-4) << x << "," << y;
      EXPECT_NEAR(r.confidence.at<float>(2 * y, 2 * x), half.confidence.at<float>(y, x), 1e-6);
    }
  }
  // A region: the whole frame's flow inside it, from pyramids of its footprint only.
  FlowOptions region = coarse;
  region.region = cv::Rect(110, 80, 90, 70);
  region.context = 8;
  const FlowResult part = dense_flow(s.frame0, s.frame1, params, region);
  const cv::Rect footprint = flow_footprint(kSize, params, region);
  EXPECT_TRUE((footprint & region.region) == region.region);
  const int align = 1 << (params.levels - 1);
  const int x0 = std::max(0, (footprint.x - 16) / align * align);
  const int y0 = std::max(0, (footprint.y - 16) / align * align);
  const cv::Rect crop = cv::Rect(cv::Point(x0, y0), footprint.br() + cv::Point(16, 16)) &
                        cv::Rect(cv::Point(), kSize);
  FlowOptions inside = region;
  inside.region = region.region - crop.tl();
  const FlowResult cropped = dense_flow(s.frame0(crop), s.frame1(crop), params, inside);
  EXPECT_LT(test::max_abs_diff(cropped.flow, part.flow), 1e-3);
  for (int bad : {-1, kMaxLevels}) {
    FlowOptions o;
    o.finest_level = bad;
    EXPECT_NE(error_message([&] {
                dense_flow(s.frame0, s.frame1, params, o);
              }).find("finest level must be in 0..5, got " + std::to_string(bad)),
              std::string::npos);
  }
}

// finest_iterations changes the iterations of the finest LK level only: equal to `iterations`
// it is the default, on one level it is `iterations`, and on several levels the coarser ones
// keep theirs (the flow differs from both uniform counts). The region's margin covers the
// larger count, so a region's flow stays the whole frame's.
TEST(DenseLkTest, FinestIterationsApplyToTheFinestLevelOnly) {
  const Scene s = make_scene(SceneKind::Rotation, kSize, 4);
  const LkParams paper = LkParams::paper();
  const FlowResult base = dense_flow(s.frame0, s.frame1, paper);
  LkParams same = paper;
  same.finest_iterations = paper.iterations;
  EXPECT_EQ(test::max_abs_diff(dense_flow(s.frame0, s.frame1, same).flow, base.flow), 0.0);

  LkParams one_level = paper;
  one_level.levels = 1;
  one_level.iterations = 5;
  one_level.finest_iterations = 2;
  LkParams two_iterations = one_level;
  two_iterations.iterations = 2;
  two_iterations.finest_iterations = 0;
  EXPECT_EQ(test::max_abs_diff(dense_flow(s.frame0, s.frame1, one_level).flow,
                               dense_flow(s.frame0, s.frame1, two_iterations).flow),
            0.0);

  LkParams cheap = paper;
  cheap.finest_iterations = 1;
  LkParams uniform_one = paper;
  uniform_one.iterations = 1;
  const FlowResult r = dense_flow(s.frame0, s.frame1, cheap);
  EXPECT_GT(test::max_abs_diff(r.flow, base.flow), 1e-3);
  EXPECT_GT(test::max_abs_diff(r.flow, dense_flow(s.frame0, s.frame1, uniform_one).flow), 1e-3);
  EXPECT_EQ(cheap.iterations_at(0, 0), 1);
  EXPECT_EQ(cheap.iterations_at(1, 0), paper.iterations);
  EXPECT_EQ(cheap.iterations_at(1, 1), 1);
  EXPECT_LT(interior_errors(r.flow, s.flow).epe, 1.2 * interior_errors(base.flow, s.flow).epe);

  LkParams more = paper;
  more.iterations = 1;
  more.finest_iterations = 6;
  const FlowResult whole = dense_flow(s.frame0, s.frame1, more);
  FlowOptions options;
  options.region = cv::Rect(117, 83, 64, 48);
  const FlowResult part = dense_flow(s.frame0, s.frame1, more, options);
  EXPECT_LT(test::max_abs_diff(part.flow, whole.flow(options.region)), 0.03);
}

// ---------------------------------------------------------------------------------------------
// Initial motion, confidence.

TEST(DenseLkTest, InitialMotionSeedsTheCoarsestLevel) {
  const Scene s = make_translation(kSize, {12.f, 0.f}, 8);
  LkParams params = LkParams::paper();
  params.levels = 1;
  FlowOptions options;
  options.initial_motion = {12.f, 0.f};
  const FlowErrors seeded =
      interior_errors(dense_flow(s.frame0, s.frame1, params, options).flow, s.flow);
  options.initial_motion = {0.f, 0.f};
  const FlowErrors unseeded =
      interior_errors(dense_flow(s.frame0, s.frame1, params, options).flow, s.flow);
  EXPECT_LT(seeded.epe, 0.0008);  // measured 0.00056 px
  EXPECT_GT(unseeded.epe, 3.0);   // measured 4.42 px

  // With levels the seed is divided down to the coarsest level and doubled back up.
  params.levels = 3;
  options.initial_motion = {12.f, 0.f};
  EXPECT_LT(interior_errors(dense_flow(s.frame0, s.frame1, params, options).flow, s.flow).epe,
            0.0016);  // measured 0.00132 px
}

TEST(DenseLkTest, ConfidenceIsZeroOnFlatImageAndPositiveOnTexture) {
  const Scene s = make_scene(SceneKind::Translation, kSize, 6);
  cv::Mat f0 = s.frame0.clone(), f1 = s.frame1.clone();
  const int half = kSize.width / 2;
  f0.colRange(0, half).setTo(128);
  f1.colRange(0, half).setTo(128);
  const LkParams params = LkParams::paper();
  const FlowResult r = dense_flow(f0, f1, params);
  ASSERT_EQ(r.confidence.type(), CV_32FC1);
  ASSERT_EQ(r.confidence.size(), kSize);
  EXPECT_TRUE(all_finite(r.flow));
  EXPECT_TRUE(all_finite(r.confidence));
  double lowest = 0;
  cv::minMaxLoc(r.confidence, &lowest);
  EXPECT_GE(lowest, 0.0);

  const int margin = params.patch + 4;
  double flat_max = 0;
  cv::minMaxLoc(r.confidence(cv::Rect(0, 0, half - margin, kSize.height)), nullptr, &flat_max);
  EXPECT_LT(flat_max, 1e-9);  // measured 0
  const cv::Rect textured(half + margin, kBorder, half - margin - kBorder,
                          kSize.height - 2 * kBorder);
  EXPECT_GT(cv::mean(r.confidence(textured))[0], 4.2e-4);  // measured 5.3e-4

  FlowOptions options;
  options.region = {150, 50, 40, 30};
  const FlowResult part = dense_flow(f0, f1, params, options);
  EXPECT_EQ(part.confidence.type(), CV_32FC1);
  EXPECT_EQ(part.confidence.size(), options.region.size());
}

}  // namespace
}  // namespace roiflow::flow
