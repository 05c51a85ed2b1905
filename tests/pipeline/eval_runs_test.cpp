#include "pipeline/eval_runs.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
namespace fs = std::filesystem;

class FlowFiles : public test::TempDirTest {};

TEST_F(FlowFiles, FlowColourAndLegendAreWrittenAndNamed) {
  const eval::FlowInput in = eval::synthetic_flow_input("translation", {96, 64});
  const pipeline::FlowRun run = pipeline::run_flow(in, flow::LkParams::paper(), 1);
  ASSERT_TRUE(run.errors.has_value());
  pipeline::FlowFiles files{path("f.flo"), path("c.png"), path("l.png")};
  files.check();
  const std::vector<std::string> written = pipeline::write_flow_files(files, in, run);
  EXPECT_EQ(written, (std::vector<std::string>{files.flo, files.color, files.legend}));
  for (const std::string& f : written)
    EXPECT_TRUE(fs::exists(f)) << f;
  EXPECT_EQ(eval::read_flo(files.flo).size(), cv::Size(96, 64));
  const std::string text = pipeline::flow_text(in, run, written);
  EXPECT_EQ(text.rfind("flow 96x64 (synthetic", 0), 0u) << text;
  EXPECT_NE(text.find("wrote " + files.flo + ", " + files.color), std::string::npos) << text;
  EXPECT_NE(text.find("\nerror vs ground truth: "), std::string::npos) << text;
}

TEST_F(FlowFiles, TruthUnknownEverywhereWritesNothing) {
  eval::FlowInput in = eval::synthetic_flow_input("translation", {64, 48});
  in.truth.setTo(cv::Scalar(1e10, 1e10));  // Middlebury's "unknown"
  const pipeline::FlowRun run = pipeline::run_flow(in, flow::LkParams::paper(), 1);
  const pipeline::FlowFiles files{path("f.flo"), path("c.png"), ""};
  EXPECT_NE(test::error_message([&] {
              pipeline::write_flow_files(files, in, run);
            }).find("unknown at every pixel"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(files.flo));
  EXPECT_FALSE(fs::exists(files.color));
  const pipeline::FlowFiles bad{path("missing/f.flo"), "", ""};
  EXPECT_NE(test::error_message([&] { bad.check(); }).find("-o"), std::string::npos);
}

TEST(SweepText, TableThenOneLine) {
  pipeline::SweepRunResult r;
  r.rows.resize(2);
  r.rows[1].value = 5;
  r.written = {"out/sweep.csv", "out/patch.svg"};
  pipeline::SweepRunOptions o;
  o.pairs.resize(3);
  o.threads = 2;
  o.repeats = 1;
  const std::string text = pipeline::sweep_text(r, o);
  EXPECT_EQ(text.rfind(eval::sweep_table(r.rows), 0), 0u) << text;
  EXPECT_NE(text.find("swept 2 values over 3 pairs, 2 threads, time per pair the fastest of 1 "
                      "run; wrote out/sweep.csv, out/patch.svg\n"),
            std::string::npos)
      << text;
  o.repeats = 3;
  EXPECT_NE(pipeline::sweep_text(r, o).find("fastest of 3 runs;"), std::string::npos);
}

}  // namespace
