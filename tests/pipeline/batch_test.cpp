#include "pipeline/batch.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using pipeline::BatchRow;

BatchRow row(const std::string& video, const std::string& status, bool skipped = false) {
  BatchRow r;
  r.video = video;
  r.status = status;
  r.skipped = skipped;
  r.frames = 120;
  r.fps = 61.25;
  r.folder = "out/" + video;
  return r;
}

TEST(Batch, OneLinePerEndedVideo) {
  EXPECT_EQ(pipeline::batch_row_line(row("a.mp4", "done")),
            "done    a.mp4 (120 frames, 61.2 fps) -> out/a.mp4");
  EXPECT_EQ(pipeline::batch_row_line(row("b.mp4", "done", true)), "skipped b.mp4 (done earlier)");
  EXPECT_EQ(pipeline::batch_row_line(row("c.mp4", "failed: cannot open")),
            "failed  c.mp4: cannot open");
  EXPECT_EQ(pipeline::batch_row_line(row("d.mp4", "cancelled")), "cancelled  d.mp4");
}

TEST(Batch, TallySummaryAndEnding) {
  const std::vector<BatchRow> rows = {row("a", "done"), row("b", "done", true),
                                      row("c", "failed: x"), row("d", "cancelled"),
                                      row("e", "done")};
  const pipeline::BatchTally t = pipeline::tally(rows);
  EXPECT_EQ(t.ran, 2);
  EXPECT_EQ(t.skipped, 1);
  EXPECT_EQ(t.failed, 1);
  EXPECT_EQ(t.cancelled, 1);
  EXPECT_EQ(pipeline::batch_summary_line(rows, "out/batch.csv"),
            "batch: 5 videos: 2 run, 1 already done, 1 failed, 1 cancelled; wrote out/batch.csv");
  EXPECT_EQ(pipeline::batch_summary_line({row("a", "done")}, ""),
            "batch: 1 videos: 1 run, 0 already done, 0 failed");
  const pipeline::Ending end = pipeline::batch_ending(rows);
  EXPECT_EQ(end.exit_code, 1);
  EXPECT_EQ(end.message, "1 of 5 videos failed (see batch.csv); run again to retry them");
  EXPECT_EQ(pipeline::batch_ending({row("a", "done")}).exit_code, 0);
}

class BatchRun : public test::TempDirTest {};

TEST_F(BatchRun, CsvFollowsTheVideosInInputOrder) {
  for (const char* name : {"b.avi", "a.avi"})
    std::ofstream(path(name)) << "not a video\n";
  pipeline::BatchOptions o;
  o.out_dir = path("out");
  o.threads = 2;
  o.csv = path("batch.csv");
  std::vector<std::string> seen;
  o.on_row = [&](const BatchRow& r) {
    seen.push_back(r.video);
    // Each row is in batch.csv when on_row announces it.
    EXPECT_NE(test::read_text(o.csv).find(r.video), std::string::npos);
  };
  const std::vector<std::string> videos = {path("b.avi"), path("a.avi")};
  const std::vector<BatchRow> rows = pipeline::run_batch(videos, o);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(seen.size(), 2u);
  for (const BatchRow& r : rows)
    EXPECT_EQ(r.status.rfind("failed: ", 0), 0u) << r.status;
  const std::string csv = test::read_text(o.csv);
  const std::size_t b = csv.find("b.avi"), a = csv.find("a.avi");
  ASSERT_NE(a, std::string::npos) << csv;
  EXPECT_LT(b, a) << csv;  // input order, not the order they ended in
  EXPECT_EQ(csv.rfind("video,status,frames,fps,seconds\n", 0), 0u) << csv;
  EXPECT_EQ(pipeline::batch_ending(rows).exit_code, 1);
}

}  // namespace
