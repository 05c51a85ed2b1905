#include "eval/track_log.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using eval::TrackRecord;

class TrackLogTest : public test::TempDirTest {};

TEST_F(TrackLogTest, ReadsTheIdColumnAndLogsWrittenBeforeIt) {
  const auto with_id = eval::parse_track_csv(
      "frame,id,x,y,w,h,vx,vy,mode,lost,ms\n1,4,1,2,3,4,0,0,local,0,1\n1,9,5,6,7,8,0,0,local,1,1\n",
      "new");
  ASSERT_EQ(with_id.size(), 2u);
  EXPECT_EQ(with_id[0].id, 4);
  EXPECT_EQ(with_id[1].id, 9);
  EXPECT_EQ(with_id[1].box, cv::Rect2f(5, 6, 7, 8));
  const auto old =
      eval::parse_track_csv("frame,x,y,w,h,vx,vy,mode,lost,ms\n1,1,2,3,4,0,0,local,0,1\n", "old");
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].id, 1);
  EXPECT_EQ(old[0].box, cv::Rect2f(1, 2, 3, 4));
  for (const char* bad :
       {"1,0,1,2,3,4,0,0,local,0,1\n", "1,x,1,2,3,4,0,0,local,0,1\n", "1,2,3,4,0,0,local,0,1\n"}) {
    const std::string m = test::error_message([&] {
      eval::parse_track_csv(std::string("frame,id,x,y,w,h,vx,vy,mode,lost,ms\n") + bad, "b");
    });
    EXPECT_NE(m.find("b:2: "), std::string::npos) << m;
  }
}

TEST_F(TrackLogTest, RowsReadBackAsWritten) {
  TrackRecord r{7, {1.256f, 2, 30, 40}, {-0.0004f, 1.5f}, TrackRecord::Mode::Global, true, 2.5, 3};
  EXPECT_EQ(eval::track_csv_row(r), "7,3,1.26,2.00,30.00,40.00,0.000,1.500,global,1,2.500\n");
  EXPECT_EQ(
      eval::track_json_object(r),
      R"({"frame":7,"id":3,"x":1.26,"y":2.0,"w":30.0,"h":40.0,"vx":0.0,"vy":1.5,"mode":"global",)"
      R"("lost":true,"ms":2.5})");
  std::string csv(eval::kTrackCsvHeader);
  csv += '\n';
  csv += eval::track_csv_row(r);
  const std::vector<TrackRecord> back = eval::parse_track_csv(csv, "memory");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].id, 3);
  EXPECT_EQ(back[0].frame, 7);
  EXPECT_FLOAT_EQ(back[0].box.x, 1.26f);
  EXPECT_EQ(back[0].mode, TrackRecord::Mode::Global);
  EXPECT_TRUE(back[0].lost);
  r.box.width = -1;
  EXPECT_NE(test::error_message([&] {
              eval::check_track_record(r, "t.csv");
            }).find("track log 't.csv', frame 7: negative box size"),
            std::string::npos);
}

TEST_F(TrackLogTest, ReaderAcceptsWindowsLineEnds) {
  test::write_text(path("t.csv"),
                   "frame,x,y,w,h,vx,vy,mode,lost,ms\r\n1,1.5,2,3,4,0.1,-0.2,local,0,0.5\r\n");
  const std::vector<TrackRecord> records = eval::read_track_csv(path("t.csv"));
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].box, cv::Rect2f(1.5f, 2, 3, 4));
  EXPECT_DOUBLE_EQ(records[0].ms, 0.5);
}

TEST_F(TrackLogTest, ReaderErrorsNameFileLineAndValue) {
  const std::string header = "frame,x,y,w,h,vx,vy,mode,lost,ms\n";
  const std::string good = "1,1,2,3,4,0,0,local,0,1\n";
  struct Case {
    std::string text;
    std::string expected;  // besides the path
  };
  const std::vector<Case> cases = {
      {"", ":1: empty file"},
      {"frame,x,y,w,h,vx,vy,mode,lost\n" + good, ":1: header 'frame,x,y,w,h,vx,vy,mode,lost'"},
      {"frame, x,y,w,h,vx,vy,mode,lost,ms\n", ":1: header"},
      {header + good + "2,1,2,3,4,0,0,local,0\n", ":3: expected 10 fields"},
      {header + "1,1,2,3,4,0,0,local,0,1,9\n", ":2: expected 10 fields"},
      {header + good + "\n", ":3: expected 10 fields"},
      {header + "1.5,1,2,3,4,0,0,local,0,1\n", ":2: frame '1.5'"},
      {header + "0,1,2,3,4,0,0,local,0,1\n", ":2: frame '0'"},
      {header + "1,abc,2,3,4,0,0,local,0,1\n", ":2: x 'abc'"},
      {header + "1,1,2x,3,4,0,0,local,0,1\n", ":2: y '2x'"},
      {header + "1,1,2,,4,0,0,local,0,1\n", ":2: w ''"},
      {header + "1,1,2,3,nan,0,0,local,0,1\n", ":2: h 'nan'"},
      {header + "1,1,2,3,4,inf,0,local,0,1\n", ":2: vx 'inf'"},
      {header + "1,1,2,-3,4,0,0,local,0,1\n", ":2: negative box size -3x4"},
      {header + "1,1,2,3,4,0,0,LOCAL,0,1\n", ":2: mode 'LOCAL'"},
      {header + "1,1,2,3,4,0,0,local,2,1\n", ":2: lost '2'"},
      {header + "1,1,2,3,4,0,0,local,0, 1\n", ":2: ms ' 1'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    test::write_text(path("t.csv"), c.text);
    const std::string message = test::error_message([&] { eval::read_track_csv(path("t.csv")); });
    EXPECT_EQ(message.rfind(path("t.csv"), 0), 0u) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
  const std::string missing = path("missing.csv");
  EXPECT_NE(test::error_message([&] { eval::read_track_csv(missing); }).find(missing),
            std::string::npos);
}

// Found by fuzzing (tests/fuzz_regressions/track_csv): a double beyond the float range became an
// infinite box or velocity.
TEST_F(TrackLogTest, ValuesBeyondTheFloatRangeAreRejected) {
  const std::string header = "frame,x,y,w,h,vx,vy,mode,lost,ms\n";
  const std::string message = test::error_message(
      [&] { eval::parse_track_csv(header + "1,0,0,1,1,0,-1e39,local,0,1\n", "big.csv"); });
  EXPECT_NE(message.find("big.csv:2: vy '-1e39' is too large"), std::string::npos) << message;
  EXPECT_NE(test::error_message([&] {
              eval::parse_track_csv(header + "1,1e39,0,1,1,0,0,local,0,1\n", "x");
            }).find("x '1e39' is too large"),
            std::string::npos);
  // ms is a double: a large one is fine.
  EXPECT_EQ(eval::parse_track_csv(header + "1,0,0,1,1,0,0,local,0,1e39\n", "ok")[0].ms, 1e39);
}

}  // namespace
