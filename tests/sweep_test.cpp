#include "stages/sweep.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "flow/flo_io.hpp"
#include "flow/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::stages {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::lines_of;
using test::read_text;
using test::run_cli;

class SweepTest : public test::TempDirTest {
 protected:
  // A translation pair a.png, b.png, gt.flo under `name`/.
  EvalPair write_pair(const std::string& name, cv::Point2f motion, std::uint64_t seed) const {
    const flow::Scene scene = flow::make_translation({128, 96}, motion, seed);
    fs::create_directories(path(name));
    EvalPair pair;
    pair.name = name;
    pair.frame0 = path(name + "/a.png");
    pair.frame1 = path(name + "/b.png");
    pair.ground_truth = path(name + "/gt.flo");
    EXPECT_TRUE(cv::imwrite(pair.frame0, scene.frame0));
    EXPECT_TRUE(cv::imwrite(pair.frame1, scene.frame1));
    flow::write_flo(pair.ground_truth, scene.flow);
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

TEST_F(SweepTest, PlotsErrorAndTimeAgainstTheValue) {
  std::vector<SweepRow> rows;
  for (int i = 1; i <= 4; ++i)
    rows.push_back({SweepParam::Iterations, double(i), 10.0 / i, 1.0 / i, 2.0 * i, 3});
  rows.push_back({SweepParam::Lambda, 1e-6, 5, 0.5, 3, 3});
  rows.push_back({SweepParam::Lambda, 1e-3, 6, 0.6, 3, 3});
  const Plot it = sweep_plot(SweepParam::Iterations, rows, "middlebury");
  ASSERT_EQ(it.panels.size(), 2u);
  EXPECT_EQ(it.panels[0].series[0].x.size(), 4u);  // only the iteration rows
  EXPECT_EQ(it.panels[1].series[0].y, (std::vector<double>{2, 4, 6, 8}));
  EXPECT_NE(it.title.find("middlebury, mean of 3 pairs"), std::string::npos);
  EXPECT_TRUE(sweep_plot(SweepParam::Lambda, rows).x_log);
  write_plot_svg(path("iterations.svg"), it);
  const std::string svg = read_text(path("iterations.svg"));
  EXPECT_NE(svg.find("run time (ms per pair)"), std::string::npos);
  EXPECT_NE(svg.find("mean EPE (px)"), std::string::npos);
  EXPECT_NE(test::error_message([&] { sweep_plot(SweepParam::Sigma, rows); }).find("sigma"),
            std::string::npos);
}

class SweepCliTest : public SweepTest {
 protected:
  CliResult run(const std::vector<std::string>& args) const {
    return run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

TEST_F(SweepCliTest, WritesTheCsvAndOnePlotPerParameter) {
  const EvalPair p = write_pair("p1", {2.5f, -1.5f}, 4);
  const CliResult r =
      run({"sweep", "--pair", p.frame0, p.frame1, p.ground_truth, "--param", "iterations",
           "--values", "1,2,4", "--out", path("out"), "--threads", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> csv = lines_of(read_text(path("out/sweep.csv")));
  ASSERT_EQ(csv.size(), 4u);
  EXPECT_EQ(csv[0], "parameter,value,aae_deg,epe,ms_per_pair");
  EXPECT_EQ(csv[1].rfind("iterations,1,", 0), 0u);
  EXPECT_EQ(csv[3].rfind("iterations,4,", 0), 0u);
  EXPECT_EQ(lines_of(r.err).size(), 3u);  // one progress line per value
  EXPECT_NE(r.err.find("sweep iterations 2 (2/3)"), std::string::npos) << r.err;
  const std::string svg = read_text(path("out/iterations.svg"));
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("iterations per pyramid level"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out/patch.svg")));
  EXPECT_NE(r.out.find("wrote"), std::string::npos);
}

TEST_F(SweepCliTest, BadValuesFailWithOneLineAndNoOutput) {
  const EvalPair p = write_pair("p1", {1.f, 1.f}, 5);
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;
  };
  const std::vector<std::string> pair = {"--pair", p.frame0, p.frame1, p.ground_truth};
  const auto with_pair = [&](std::vector<std::string> args) {
    args.insert(args.begin() + 1, pair.begin(), pair.end());
    return args;
  };
  const std::vector<Case> cases = {
      {with_pair({"sweep", "--param", "patch", "--values", "5,40", "--out", path("o")}), 2,
       "patch 40"},
      {with_pair({"sweep", "--param", "iterations", "--values", "2.5", "--out", path("o")}), 2,
       "iterations 2.5"},
      {with_pair({"sweep", "--param", "lambda", "--values", "0", "--out", path("o")}), 2,
       "lambda 0"},
      {with_pair({"sweep", "--values", "3", "--out", path("o")}), 2, "--values needs one --param"},
      {with_pair({"sweep", "--param", "size", "--out", path("o")}), 2, "--param"},
      {with_pair({"sweep", "--param", "patch"}), 2, "--out"},
      {{"sweep", "--param", "patch", "--out", path("o")}, 2, "needs a Middlebury directory"},
      {with_pair({"sweep", "--param", "patch", "--out", path("missing/o")}), 1, "does not exist"},
      {{"sweep", path("nowhere"), "--out", path("o")}, 1, "does not exist"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    test::expect_one_error_line(run(c.args), c.exit_code, c.expected);
    EXPECT_FALSE(fs::exists(path("o")));
  }
}

}  // namespace
}  // namespace roiflow::stages
