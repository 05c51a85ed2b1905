// roiflow score --mot end to end: the JSON keys, the table, and one error line for bad files.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/mot.hpp"
#include "eval/traffic_scene.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
using test::CliResult;

class CliMotScoreTest : public test::TempDirTest {
 protected:
  // Ground truth: objects 1 and 2 in frames 1-4, and a conf-0 box in frame 1. The tracker
  // follows object 1 as id 7, object 2 as id 8 then 9 (one switch), misses object 2 in frame 4
  // and has a stray box in frame 4: 7 matches, FN 1, FP 1, IDSW 1 -> MOTA 1 - 3/8.
  void SetUp() override {
    TempDirTest::SetUp();
    std::ofstream gt(path("gt.txt"), std::ios::binary);
    std::ofstream pred(path("pred.txt"), std::ios::binary);
    gt << "1,3,300,300,20,20,0,1,1\n";
    for (int f = 1; f <= 4; ++f) {
      gt << f << ",1," << 10 * f << ",10,20,40,1,1,1\n"
         << f << ",2,200," << 10 * f << ",30,30,1,1,1\n";
      pred << f << ",7," << 10 * f + 1 << ",10,20,40,1,-1,-1,-1\n";
      if (f < 4) pred << f << "," << (f == 1 ? 8 : 9) << ",200," << 10 * f << ",30,30,1,-1,-1,-1\n";
    }
    pred << "4,12,500,500,10,10,1,-1,-1,-1\n";
  }
  CliResult run(const std::vector<std::string>& args) const {
    return test::run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

TEST_F(CliMotScoreTest, JsonHasTheIssueKeys) {
  const CliResult r = run({"score", "--mot", path("pred.txt"), path("gt.txt"), "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& item : doc.items())
    keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"fn", "fp", "frames", "id_switches", "idf1", "mota",
                                            "motp", "objects"}));
  EXPECT_NEAR(doc["mota"].get<double>(), 1.0 - 3.0 / 8.0, 1e-12);
  EXPECT_EQ(doc["id_switches"], 1);
  EXPECT_EQ(doc["fp"], 1);
  EXPECT_EQ(doc["fn"], 1);
  EXPECT_EQ(doc["frames"], 4);
  EXPECT_EQ(doc["objects"], 2);
  // IoU of object 1's boxes shifted by 1 px: 19*40 / (2*800 - 760) = 760/840; object 2 exact.
  EXPECT_NEAR(doc["motp"].get<double>(), (4 * 760.0 / 840.0 + 3) / 7, 1e-12);
  // IDTP: 1<->7 four frames, 2<->9 two frames = 6; IDF1 = 12 / (8 + 8).
  EXPECT_NEAR(doc["idf1"].get<double>(), 0.75, 1e-12);
}

TEST_F(CliMotScoreTest, Table) {
  const CliResult r = run({"score", "--mot", path("pred.txt"), path("gt.txt")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("MOTA           0.6250"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("IDF1           0.7500"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ID switches    1"), std::string::npos) << r.out;
}

TEST_F(CliMotScoreTest, BadFilesFailWithOneLine) {
  std::ofstream(path("short.txt"), std::ios::binary) << "1,1,0,0,10,10\n2,1,0,0,10\n";
  std::ofstream(path("zero.txt"), std::ios::binary) << "1,1,0,0,10,10,0\n";
  test::expect_one_error_line(run({"score", "--mot", path("short.txt"), path("gt.txt")}), 1,
                              path("short.txt") + ":2: expected 6 to 10 fields");
  test::expect_one_error_line(run({"score", "--mot", path("pred.txt"), path("missing.txt")}), 1,
                              "cannot read ground truth '" + path("missing.txt") + "'");
  test::expect_one_error_line(run({"score", "--mot", path("pred.txt"), path("zero.txt")}), 1,
                              "no box to score");
  test::expect_one_error_line(run({"score", "--mot", path("pred.txt")}), 2, "GROUNDTRUTH");
}

TEST_F(CliMotScoreTest, SyntheticTrafficInputAsGroundTruth) {
  eval::TrafficSceneParams p;
  p.size = {320, 240};
  p.frames = 30;
  p.objects = 4;
  std::vector<eval::MotBox> truth = eval::TrafficScene(p).ground_truth();
  eval::write_mot(path("exact.txt"), truth);
  CliResult r =
      run({"score", "--mot", path("exact.txt"), "synthetic:30:320x240:4", "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json doc = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(doc["mota"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(doc["idf1"].get<double>(), 1.0);
  EXPECT_EQ(doc["frames"], 30);
  // One vehicle dropped: its boxes are all misses.
  const int dropped = truth.front().id;
  long long boxes = 0;
  std::erase_if(truth, [&](const eval::MotBox& b) {
    boxes += b.id == dropped;
    return b.id == dropped;
  });
  eval::write_mot(path("missing.txt"), truth);
  r = run({"score", "--mot", path("missing.txt"), "synthetic:30:320x240:4", "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc["fn"], boxes);
  EXPECT_LT(doc["mota"].get<double>(), 1.0);
  test::expect_one_error_line(run({"score", "--mot", path("exact.txt"), "synthetic:30"}), 1,
                              "only synthetic inputs with OBJECTS");
  test::expect_one_error_line(run({"score", "--mot", path("exact.txt"), "synthetic:30:999"}), 1,
                              "bad synthetic input 'synthetic:30:999'");
}

}  // namespace
