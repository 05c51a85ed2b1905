#include "eval/sweep.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;
using test::lines_of;
using test::read_text;

class SweepTest : public test::TempDirTest {
 protected:
  // A translation pair a.png, b.png, gt.flo under `name`/.
  EvalPair write_pair(const std::string& name, cv::Point2f motion, std::uint64_t seed) const {
    const eval::Scene scene = eval::make_translation({128, 96}, motion, seed);
    fs::create_directories(path(name));
    EvalPair pair;
    pair.name = name;
    pair.frame0 = path(name + "/a.png");
    pair.frame1 = path(name + "/b.png");
    pair.ground_truth = path(name + "/gt.flo");
    EXPECT_TRUE(cv::imwrite(pair.frame0, scene.frame0));
    EXPECT_TRUE(cv::imwrite(pair.frame1, scene.frame1));
    eval::write_flo(pair.ground_truth, scene.flow);
    return pair;
  }
};

TEST_F(SweepTest, OneRowPerValueWithTheMeanOverThePairs) {
  const std::vector<EvalPair> pairs = {write_pair("p1", {1.3f, -0.7f}, 1),
                                       write_pair("p2", {-2.1f, 0.9f}, 2)};
  const flow::LkParams base = flow::LkParams::paper();
  std::vector<std::size_t> progress;
  const std::vector<SweepRow> rows =
      sweep(pairs, base, SweepParam::Patch, {5, 9, 15}, nullptr,
            [&](const SweepRow&, std::size_t i) { progress.push_back(i); });
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(progress, (std::vector<std::size_t>{0, 1, 2}));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].param, SweepParam::Patch);
    EXPECT_EQ(rows[i].pairs, 2);
    EXPECT_GT(rows[i].ms_per_pair, 0.0);
    EXPECT_LT(rows[i].epe, 0.5);  // small sub-pixel translations are easy
  }
  EXPECT_EQ(rows[1].value, 9);
  // The row is the mean of evaluate_pair at that value (dense LK is deterministic).
  flow::LkParams p9 = base;
  p9.patch = 9;
  const double aae =
      (evaluate_pair(pairs[0], p9).errors.aae_deg + evaluate_pair(pairs[1], p9).errors.aae_deg) / 2;
  EXPECT_NEAR(rows[1].aae_deg, aae, 1e-9);

  const std::vector<std::string> csv = lines_of(sweep_csv(rows));
  ASSERT_EQ(csv.size(), 4u);
  EXPECT_EQ(csv[0], "parameter,value,aae_deg,epe,ms_per_pair");
  EXPECT_EQ(csv[2].rfind("patch,9,", 0), 0u) << csv[2];
}

TEST_F(SweepTest, OneIterationIsWorseThanThreeOnALargeMotion) {
  // 2.5 px without a pyramid: one linearisation around zero motion falls well short.
  const std::vector<EvalPair> pairs = {write_pair("big", {2.5f, -1.75f}, 3)};
  flow::LkParams base = flow::LkParams::paper();
  base.levels = 1;
  const std::vector<SweepRow> rows =
      sweep(pairs, base, SweepParam::Iterations, {1, 3}, nullptr, {}, 2);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_GT(rows[0].epe, rows[1].epe * 2) << rows[0].epe << " vs " << rows[1].epe;
  EXPECT_GT(rows[0].aae_deg, rows[1].aae_deg);
}

TEST(SweepValues, DefaultsCoverThePapersRanges) {
  const flow::LkParams base = flow::LkParams::paper();
  const std::vector<double> patch = default_sweep_values(SweepParam::Patch, base);
  ASSERT_EQ(patch.size(), 29u);  // every size 3..31, even ones included
  EXPECT_EQ(patch.front(), 3);
  EXPECT_EQ(patch.back(), 31);
  EXPECT_EQ(default_sweep_values(SweepParam::Iterations, base).size(), 10u);
  EXPECT_EQ(default_sweep_values(SweepParam::Levels, base).back(), 6);
  flow::LkParams odd = base;
  odd.sigma = 0.6;
  odd.lambda = 3e-6;
  const auto sigma = default_sweep_values(SweepParam::Sigma, odd);
  EXPECT_NE(std::find(sigma.begin(), sigma.end(), 0.6), sigma.end());
  EXPECT_TRUE(std::is_sorted(sigma.begin(), sigma.end()));
  const auto lambda = default_sweep_values(SweepParam::Lambda, odd);
  EXPECT_NE(std::find(lambda.begin(), lambda.end(), 3e-6), lambda.end());
  for (SweepParam p : all_sweep_params()) {
    for (double v : default_sweep_values(p, base))
      EXPECT_NO_THROW(with_value(base, p, v)) << to_string(p) << " " << v;
  }
}

TEST(SweepValues, AbsurdValuesThrowNamingThem) {
  const flow::LkParams base = flow::LkParams::paper();
  EXPECT_EQ(with_value(base, SweepParam::Lambda, 1e-4).lambda, 1e-4);
  EXPECT_EQ(with_value(base, SweepParam::Levels, 5).levels, 5);
  EXPECT_NE(test::error_message([&] {
              with_value(base, SweepParam::Patch, 40);
            }).find("patch 40: patch must be in 3..31"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] {
              with_value(base, SweepParam::Iterations, 2.5);
            }).find("iterations 2.5"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { with_value(base, SweepParam::Lambda, 0); }).find("lambda 0"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { with_value(base, SweepParam::Sigma, NAN); }).find("sigma"),
            std::string::npos);
  EXPECT_NE(test::error_message([] { sweep_param_from_string("patches"); }).find("'patches'"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { sweep({}, base, SweepParam::Patch, {3}); }).find("no pair"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] {
              sweep({EvalPair{}}, base, SweepParam::Patch, {3}, nullptr, {}, 0);
            }).find("repeats must be in 1..100, got 0"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::eval
