// roiflow scaling end to end: the CSV and SVG it writes, and one error line for bad options.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using test::CliResult;
namespace fs = std::filesystem;

class CliScalingTest : public test::TempDirTest {
 protected:
  CliResult run(const std::vector<std::string>& args) const {
    return test::run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

TEST_F(CliScalingTest, WritesCsvAndSvg) {
  const CliResult r = run({"scaling", "synthetic:8:128x96:2", "--threads", "1,2", "--mode", "dense",
                           "--out", path("out")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = test::lines_of(test::read_text(path("out/scaling.csv")));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "threads,fps,tracker_fps,speedup,efficiency");
  EXPECT_EQ(lines[1].rfind("1,", 0), 0u);
  EXPECT_NE(lines[1].find(",1.000,1.000"), std::string::npos) << lines[1];
  EXPECT_EQ(test::split(lines[2], ',').size(), 5u);
  EXPECT_NE(test::read_text(path("out/scaling.svg")).find("<svg"), std::string::npos);
  EXPECT_NE(r.out.find("scaling dense mode"), std::string::npos) << r.out;
}

TEST_F(CliScalingTest, BadOptionsFailWithOneLine) {
  test::expect_one_error_line(run({"scaling", "synthetic:8", "--threads", "0", "--out", path("o")}),
                              2, "got 0");
  test::expect_one_error_line(
      run({"scaling", "synthetic:8", "--threads", "2,2", "--out", path("o")}), 2, "given twice");
  test::expect_one_error_line(run({"scaling", "synthetic:8", "--out", path("o")}), 2, "--threads");
  test::expect_one_error_line(
      run({"scaling", "synthetic:8", "--threads", "1", "--mode", "fast", "--out", path("o")}), 2,
      "--mode");
  test::expect_one_error_line(
      run({"scaling", "synthetic:8", "--threads", "1", "--out", path("no/such/dir")}), 1,
      "does not exist");
  test::expect_one_error_line(
      run({"scaling", path("missing.avi"), "--threads", "1", "--out", path("o")}), 1,
      "missing.avi");
  EXPECT_FALSE(fs::exists(path("o/scaling.csv")));
}

}  // namespace
