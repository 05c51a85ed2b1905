// End-to-end tests of `roiflow eval` on Sintel and KITTI trees and of its HTML report.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/synthetic.hpp"
#include "eval_test_trees.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;
using test::CliResult;
using test::read_text;
using test::run_cli;
using test::split;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}
class EvalCliTest : public test::TempDirTest {
 protected:
  CliResult run(const std::vector<std::string>& args) const {
    return run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }

  // CSV rows (header first) of a successful run.
  std::vector<std::vector<std::string>> csv(const std::vector<std::string>& args) const {
    const CliResult r = run(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::vector<std::vector<std::string>> rows;
    for (const std::string& line : split(r.out, '\n'))
      rows.push_back(split(line, ','));
    return rows;
  }
};

const std::vector<std::string> kExtendedHeader = {"sequence", "aae_deg", "epe",    "r1",
                                                  "r3",       "ms",      "fl",     "aae_deg_noc",
                                                  "epe_noc",  "r1_noc",  "r3_noc", "fl_noc"};

// The hand case of eval_test_trees.hpp, in the CSV's decimals.
void expect_hand_row(const std::vector<std::string>& row) {
  ASSERT_EQ(row.size(), kExtendedHeader.size());
  EXPECT_EQ(row[2], "2.7500");  // EPE, all
  EXPECT_EQ(row[4], "50.00");   // R3
  EXPECT_EQ(row[6], "50.00");   // Fl, all
  EXPECT_EQ(row[8], "2.0000");  // EPE, non-occluded
  EXPECT_EQ(row[11], "33.33");  // Fl, non-occluded
}

TEST_F(EvalCliTest, SintelTreeGivesTheHandComputedErrors) {
  test::write_sintel_tree(dir_ / "MPI-Sintel/training", {"alley_1", "cave_2"}, 2);
  const auto rows = csv({"eval", path("MPI-Sintel"), "--format", "csv"});
  ASSERT_EQ(rows.size(), 6u);  // header, 4 pairs, mean
  EXPECT_EQ(rows[0], kExtendedHeader);
  EXPECT_EQ(rows[1][0], "alley_1/frame_0001");
  EXPECT_EQ(rows[4][0], "cave_2/frame_0002");
  EXPECT_EQ(rows[5][0], "mean");
  for (std::size_t i = 1; i < rows.size(); ++i)
    expect_hand_row(rows[i]);

  const auto scene = csv({"eval", path("MPI-Sintel"), "--format", "csv", "--pass", "final",
                          "--scene", "cave_2", "--layout", "sintel"});
  ASSERT_EQ(scene.size(), 4u);
  EXPECT_EQ(scene[1][0], "cave_2/frame_0001");
  EXPECT_EQ(scene[2][0], "cave_2/frame_0002");

  const auto thinned = csv({"eval", path("MPI-Sintel"), "--format", "csv", "--max-pairs", "2"});
  ASSERT_EQ(thinned.size(), 4u);
  EXPECT_EQ(thinned[1][0], "alley_1/frame_0001");
  EXPECT_EQ(thinned[2][0], "cave_2/frame_0001");
}

TEST_F(EvalCliTest, KittiTreeGivesTheHandComputedErrorsInEveryFormat) {
  test::write_kitti_tree(dir_ / "kitti", {0, 12});
  const auto rows = csv({"eval", path("kitti"), "--format", "csv"});
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], kExtendedHeader);
  EXPECT_EQ(rows[1][0], "000000");
  EXPECT_EQ(rows[2][0], "000012");
  for (std::size_t i = 1; i < rows.size(); ++i)
    expect_hand_row(rows[i]);

  const CliResult json = run({"eval", path("kitti"), "--format", "json", "-o", path("k.json")});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json doc = nlohmann::json::parse(read_text(path("k.json")));
  ASSERT_EQ(doc["rows"].size(), 2u);
  EXPECT_EQ(doc["rows"][0]["pixels"], test::kHandPixelsAll);
  EXPECT_EQ(doc["rows"][0]["noc"]["pixels"], test::kHandPixelsNoc);
  EXPECT_NEAR(doc["mean"]["noc"]["epe"].get<double>(), test::kHandEpeNoc, 1e-6);

  const CliResult table = run({"eval", path("kitti")});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("Fl-noc(%)"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("\nmean"), std::string::npos) << table.out;
}

TEST_F(EvalCliTest, PairWithKittiGroundTruthShowsFl) {
  test::write_kitti_tree(dir_, {5}, "image_2", /*noc=*/false);
  const auto rows = csv({"eval", "--format", "csv", "--pair", path("image_2/000005_10.png"),
                         path("image_2/000005_11.png"), path("flow_occ/000005_10.png")});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], kExtendedHeader);
  ASSERT_EQ(rows[1].size(), 11u);  // getline drops the last, empty field
  for (std::size_t i = 7; i < 11; ++i)
    EXPECT_EQ(rows[1][i], "") << i;  // no noc figures for a --pair
  EXPECT_EQ(rows[1][0], "pair1");
  EXPECT_EQ(rows[1][2], "2.7500");
  EXPECT_EQ(rows[1][6], "50.00");
}

TEST_F(EvalCliTest, ReportCoversEveryPairOfEachLayout) {
  test::write_sintel_tree(dir_ / "sintel", {"alley_1", "cave_2"}, 1);
  test::write_kitti_tree(dir_ / "kitti", {3});
  const eval::Scene scene = eval::make_translation({96, 64}, {1.3f, -0.7f});
  test::write_png(dir_ / "mb/Venus/frame10.png", scene.frame0);
  test::write_png(dir_ / "mb/Venus/frame11.png", scene.frame1);
  eval::write_flo(path("mb/Venus/flow10.flo"), scene.flow);

  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> names;
  };
  const std::vector<Case> cases = {
      {{"eval", path("sintel"), "--report", path("r.html")},
       {"alley_1/frame_0001", "cave_2/frame_0001"}},
      {{"eval", path("kitti"), "--report", path("r.html"), "--format", "csv"}, {"000003"}},
      {{"eval", path("mb"), "--report", path("r.html"), "-o", path("e.csv")}, {"Venus"}},
      {{"eval", "--pair", path("mb/Venus/frame10.png"), path("mb/Venus/frame11.png"),
        path("mb/Venus/flow10.flo"), "--report", path("r.html")},
       {"pair1"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[1]);
    fs::remove(path("r.html"));
    const CliResult r = run(c.args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("wrote report " + path("r.html")), std::string::npos) << r.out;
    const std::string html = read_text(path("r.html"));
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    EXPECT_EQ(count(html, "<section "), c.names.size());
    EXPECT_EQ(count(html, "<img "), 5 * c.names.size() + 1);
    EXPECT_EQ(count(html, "src=\"data:image/"), 5 * c.names.size() + 1);
    for (const std::string& name : c.names)
      EXPECT_NE(html.find("<h2>" + name + "</h2>"), std::string::npos) << name;
  }
}

TEST_F(EvalCliTest, BadTreesAndOptionsFailInOneLineLeavingNoFile) {
  test::write_sintel_tree(dir_ / "sintel", {"alley_1"}, 2);
  fs::remove(path("sintel/clean/alley_1/frame_0003.png"));
  test::write_kitti_tree(dir_ / "kitti", {0});
  fs::create_directories(path("empty"));
  const std::string out = path("out.csv");
  const std::string report = path("r.html");
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{"eval", path("sintel"), "-o", out, "--report", report}, 1, "frame_0003.png"},
      {{"eval", path("sintel"), "--pass", "final", "--layout", "kitti", "--report", report},
       1,
       "KITTI"},
      {{"eval", path("kitti"), "--scene", "000099", "--report", report}, 1, "000099"},
      {{"eval", path("empty"), "--report", report}, 1, "Middlebury, Sintel or KITTI"},
      {{"eval", path("kitti"), "--report", path("no/such/dir/r.html")}, 1, "--report"},
      {{"eval", path("kitti"), "--max-pairs", "-1", "--report", report}, 2, "max-pairs"},
      {{"eval", path("kitti"), "--pass", "sepia", "--report", report}, 2, "pass"},
      {{"eval", path("kitti"), "--layout", "hd1k", "--report", report}, 2, "layout"},
      {{"eval", "--pair", "a.png", "b.png", "gt.png", "--scene", "x", "--report", report},
       2,
       "scene"},
  };
  for (const Case& c : cases) {
    std::string shown;
    for (const std::string& arg : c.args)
      shown += " " + arg;
    SCOPED_TRACE("roiflow" + shown);
    test::expect_one_error_line(run(c.args), c.exit_code, c.expected);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(report));
  }
}

}  // namespace
