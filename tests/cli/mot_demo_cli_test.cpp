// roiflow demo --objects end to end: the files, the summary's MOTA and IDF1, what it prints.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/mot.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
namespace fs = std::filesystem;

class CliMotDemoTest : public test::TempDirTest {
 protected:
  test::CliResult run(const std::vector<std::string>& args) const {
    return test::run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

TEST_F(CliMotDemoTest, WritesMotAndGroundTruthAndPrintsTheScores) {
  const test::CliResult r = run({"demo", "--objects", "2", "--frames", "20", "--threads", "2",
                                 "--dir", path("demo"), "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"mot.txt", "gt_mot.txt", "track.csv", "demo.mp4", "summary.json"})
    EXPECT_TRUE(fs::is_regular_file(path(std::string("demo/") + f))) << f;
  const nlohmann::json summary = nlohmann::json::parse(test::read_text(path("demo/summary.json")));
  const eval::MotScore s = eval::score_mot(eval::read_mot(path("demo/mot.txt"), "tracker output"),
                                           eval::read_mot(path("demo/gt_mot.txt"), "ground truth"));
  EXPECT_DOUBLE_EQ(summary.at("mota").get<double>(), s.mota);
  EXPECT_DOUBLE_EQ(summary.at("idf1").get<double>(), s.idf1);
  EXPECT_EQ(summary.at("frames"), 20);
  char expected[64];
  std::snprintf(expected, sizeof expected, "MOTA %.3f, IDF1 %.3f", s.mota, s.idf1);
  EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("20 frames, 2 vehicles"), std::string::npos) << r.out;
}

TEST_F(CliMotDemoTest, BadObjectCountIsAUsageError) {
  test::expect_one_error_line(run({"demo", "--objects", "0", "--dir", path("d")}), 2, "--objects");
  test::expect_one_error_line(run({"demo", "--objects", "300", "--dir", path("d")}), 2,
                              "--objects");
  EXPECT_FALSE(fs::exists(path("d")));
}

}  // namespace
