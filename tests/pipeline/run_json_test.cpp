#include "pipeline/run_json.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/compare.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;

class RunJson : public test::TempDirTest {};

TEST_F(RunJson, FinishRunWritesTheSummaryAndListsWhatWasWritten) {
  const nlohmann::ordered_json doc = {{"frames", 12}};
  EXPECT_EQ(pipeline::finish_run("", doc, "text\n", {}), "text\n");
  EXPECT_EQ(pipeline::finish_run("", doc, "text\n", {"a.csv", "b.avi"}),
            "text\n  wrote a.csv, b.avi\n");
  EXPECT_EQ(pipeline::finish_run(path("s.json"), doc, "t\n", {"a.csv"}),
            "t\n  wrote a.csv, " + path("s.json") + "\n");
  EXPECT_EQ(nlohmann::json::parse(test::read_text(path("s.json"))).at("frames"), 12);
  EXPECT_EQ(pipeline::finish_run("", doc, "t\n", {"", "b.avi", ""}), "t\n  wrote b.avi\n");
}

TEST_F(RunJson, TrackSummaryDocumentSaysHowTheRunEnded) {
  pipeline::TrackSummary s;
  s.input = "clip.avi";
  s.status = "end of stream";
  s.frames = 5;
  nlohmann::ordered_json doc = pipeline::summary_json(s, {});
  EXPECT_EQ(doc.at("input"), "clip.avi");
  EXPECT_EQ(doc.at("status"), "end of stream");
  EXPECT_EQ(doc.at("frames"), 5);
  doc = pipeline::summary_json(s, {1, "input stopped at frame 5"});
  EXPECT_EQ(doc.at("status"), "input stopped at frame 5");
}

TEST_F(RunJson, TrackOutputsAreCheckedByOption) {
  pipeline::check_track_outputs(path("t.csv"), path("v.avi"), path("s.json"), path("m.txt"));
  pipeline::check_track_outputs("", "", "");
  const std::string missing = path("no/such/dir/x");
  EXPECT_NE(test::error_message([&] {
              pipeline::check_track_outputs(missing + ".csv", "", "");
            }).find("--log"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] {
              pipeline::check_track_outputs("", "", "", missing);
            }).find("--mot"),
            std::string::npos);
  EXPECT_NE(
      test::error_message([&] { pipeline::check_track_outputs("", missing, ""); }).find("--out"),
      std::string::npos);
  EXPECT_NE(test::error_message([&] {
              pipeline::check_track_outputs("", "", missing);
            }).find("--summary"),
            std::string::npos);
}

TEST(RunText, DenseSummaryLine) {
  pipeline::DenseSummary s;
  s.input = "clip.avi";
  s.pairs = 9;
  s.wall_s = 1.234;
  s.fps = 7.29;
  s.threads = 2;
  EXPECT_EQ(pipeline::summary_text(s),
            "dense clip.avi: 9 pairs in 1.23 s, 7.3 pairs/s, 2 threads\n");
}

TEST(CompareText, TableFilesAndEnding) {
  pipeline::CompareResult r;
  pipeline::CompareOptions o;
  o.out_dir = "out/cmp";
  const std::string text = pipeline::compare_text(r, o, {"out/cmp/compare.csv"});
  EXPECT_EQ(text.rfind(pipeline::compare_table(r, o), 0), 0u) << text;
  EXPECT_NE(text.find("  wrote out/cmp/compare.csv\n  per-mode logs and summaries: "
                      "out/cmp/{local,global}.{csv,json}\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(pipeline::compare_ending(r).exit_code, 0);
  r.cancelled = true;
  const pipeline::Ending end = pipeline::compare_ending(r);
  EXPECT_GE(end.exit_code, 128);
  EXPECT_NE(end.message.find("during the compare runs; no comparison written"), std::string::npos);
}

}  // namespace
