// roiflow sweep end to end: the CSV, one plot per parameter, and one error line for bad values.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/flow_eval.hpp"
#include "eval/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::eval {
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
}  // namespace roiflow::eval
