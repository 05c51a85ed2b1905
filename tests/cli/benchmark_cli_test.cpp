// roiflow benchmark end to end: the table on stdout and the four files, and one error line with
// no output for bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "otb_test_tree.hpp"
#include "test_util.hpp"

namespace roiflow {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::lines_of;
using test::read_text;

class BenchmarkCliTest : public test::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    test::OtbSequenceSpec a;
    a.frames = 12;
    a.absent = {4};
    test::write_otb_sequence(dir_ / "set" / "alpha", a);
    test::OtbSequenceSpec b;
    b.frames = 10;
    b.seed = 3;
    b.tiny_tlp = true;
    test::write_otb_sequence(dir_ / "set" / "beta", b);
  }
  CliResult run(const std::vector<std::string>& args) const {
    return test::run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

TEST_F(BenchmarkCliTest, PrintsTheTableAndWritesTablesAndPlots) {
  const CliResult r = run({"benchmark", path("set"), "--out", path("out"), "--trackers",
                           "roiflow,mosse", "--threads", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| sequence | roiflow | mosse |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| alpha | "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| **mean** | **"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("benchmarked 2 trackers on 2 sequences"), std::string::npos) << r.out;
  EXPECT_EQ(lines_of(r.err).size(), 2u) << r.err;  // one progress line per sequence
  const std::vector<std::string> csv = lines_of(read_text(path("out/benchmark.csv")));
  ASSERT_EQ(csv.size(), 1u + 4u + 2u);
  EXPECT_EQ(csv[1].rfind("alpha,roiflow,12,11,", 0), 0u) << csv[1];
  EXPECT_EQ(csv[3].rfind("beta,roiflow,10,10,", 0), 0u) << csv[3];
  EXPECT_EQ(csv[6].rfind("mean,mosse,22,21,", 0), 0u) << csv[6];
  EXPECT_NE(r.out.find(read_text(path("out/benchmark.md"))), std::string::npos);
  EXPECT_NE(read_text(path("out/success.svg")).find("Success plots of OPE (2 sequences)"),
            std::string::npos);
  EXPECT_NE(read_text(path("out/precision.svg")).find("Precision plots of OPE"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out/tracks")));
}

TEST_F(BenchmarkCliTest, TracksWritesALogPerRunThatScoreReads) {
  const CliResult r = run({"benchmark", path("set"), "--out", path("out"), "--trackers",
                           "roiflow,kcf", "--sequences", "beta", "--tracks", "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* tracker : {"roiflow", "kcf"}) {
    SCOPED_TRACE(tracker);
    const std::string log = path(std::string("out/tracks/beta/") + tracker + ".csv");
    const std::vector<std::string> lines = lines_of(read_text(log));
    ASSERT_EQ(lines.size(), 11u);
    EXPECT_EQ(lines[0], "frame,id,x,y,w,h,vx,vy,mode,lost,ms");
    const CliResult s =
        run({"score", log, path("set/beta/groundtruth_rect.txt"), "--format", "json"});
    EXPECT_EQ(s.exit_code, 0) << s.err;
    EXPECT_NE(s.out.find("\"frames\": 10"), std::string::npos) << s.out;
  }
  EXPECT_FALSE(fs::exists(path("out/tracks/alpha")));
}

TEST_F(BenchmarkCliTest, BadInputFailsWithOneLineAndNoOutput) {
  fs::create_directories(path("empty/folder"));
  std::ofstream(path("a_file")) << "x";
  test::OtbSequenceSpec spec;
  spec.frames = 5;
  test::write_otb_sequence(dir_ / "wrong" / "seq", spec);
  std::ofstream(path("wrong/seq/groundtruth_rect.txt"), std::ios::app) << "1,2,3,4\n";
  test::write_otb_sequence(dir_ / "nan" / "seq", spec);
  std::ofstream(path("nan/seq/groundtruth_rect.txt"), std::ios::app) << "1,NaN,3,4\n";
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;
  };
  const std::string out = path("o");
  const std::vector<Case> cases = {
      {{"benchmark", path("missing"), "--out", out}, 1, "is not a directory"},
      {{"benchmark", path("empty"), "--out", out}, 1, "holds no sequence"},
      {{"benchmark", path("set"), "--out", out, "--trackers", "roiflow,tld"},
       2,
       "--trackers: unknown tracker 'tld' (known: roiflow, csrt, kcf, mosse, medianflow)"},
      {{"benchmark", path("set"), "--out", out, "--trackers", "csrt,csrt"}, 1, "listed twice"},
      {{"benchmark", path("set"), "--out", out, "--sequences", "gamma"}, 1, "no sequence 'gamma'"},
      {{"benchmark", path("wrong"), "--out", out}, 1, "holds 6 boxes but the sequence has 5"},
      {{"benchmark", path("nan"), "--out", out}, 1, "groundtruth_rect.txt:6: partly NaN box"},
      {{"benchmark", path("set"), "--out", path("a_file")}, 1, "is not a directory"},
      {{"benchmark", path("set")}, 2, "--out"},
      {{"benchmark", path("set"), "--out", out, "--threads", "0"}, 2, "--threads"},
      {{"benchmark", path("set"), "--out", out, "--init-shift", "1"}, 2, "--init-shift"},
      {{"benchmark", path("set"), "--out", out, "--init-shift", "1,x"}, 2, "--init-shift"},
      {{"benchmark", path("set"), "--out", out, "--init-shift", "1,1e9"},
       1,
       "init shift must be finite and at most 1000 pixels"},
      {{"benchmark", path("set"), "--out", out, "--init-shift=-900,0"},
       1,
       "shifted by --init-shift leaves the"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    test::expect_one_error_line(run(c.args), c.exit_code, c.expected);
    EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace roiflow
