#include "video/track_log_sink.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using eval::TrackRecord;
using test::read_text;
using video::TrackLogWriter;

// Values chosen to exercise the rounding: 2 decimals for the box, 3 for velocity and ms.
std::vector<TrackRecord> sample_records() {
  return {
      {1, {70, 51, 107, 87}, {0, 0}, TrackRecord::Mode::Global, false, 12.5},
      {2,
       {71.256f, 50.5f, 107, 86.994f},
       {1.2564f, -0.0004f},
       TrackRecord::Mode::Local,
       false,
       0.4321},
      {3, {300, 200.25f, 0, 0}, {-3.5f, 2}, TrackRecord::Mode::Global, true, 7},
  };
}

void write_all(const std::string& path, const std::vector<TrackRecord>& records) {
  TrackLogWriter log(path);
  for (const TrackRecord& r : records)
    log.write(r);
  log.close();
}

class TrackLogTest : public test::TempDirTest {};

TEST_F(TrackLogTest, CsvHasExactHeaderAndFixedDecimals) {
  write_all(path("t.csv"), sample_records());
  EXPECT_EQ(read_text(path("t.csv")),
            "frame,id,x,y,w,h,vx,vy,mode,lost,ms\n"
            "1,1,70.00,51.00,107.00,87.00,0.000,0.000,global,0,12.500\n"
            "2,1,71.26,50.50,107.00,86.99,1.256,0.000,local,0,0.432\n"
            "3,1,300.00,200.25,0.00,0.00,-3.500,2.000,global,1,7.000\n");
}

TEST_F(TrackLogTest, CsvRoundTripKeepsTheWrittenValues) {
  write_all(path("t.csv"), sample_records());
  const std::vector<TrackRecord> back = eval::read_track_csv(path("t.csv"));
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[0].frame, 1);
  EXPECT_EQ(back[0].box, cv::Rect2f(70, 51, 107, 87));
  EXPECT_EQ(back[0].mode, TrackRecord::Mode::Global);
  EXPECT_DOUBLE_EQ(back[0].ms, 12.5);
  EXPECT_FLOAT_EQ(back[1].box.x, 71.26f);
  EXPECT_FLOAT_EQ(back[1].box.height, 86.99f);
  EXPECT_FLOAT_EQ(back[1].velocity.x, 1.256f);
  EXPECT_EQ(back[1].mode, TrackRecord::Mode::Local);
  EXPECT_FALSE(back[1].lost);
  EXPECT_DOUBLE_EQ(back[1].ms, 0.432);
  EXPECT_EQ(back[2].frame, 3);
  EXPECT_EQ(back[2].velocity, cv::Point2f(-3.5f, 2));
  EXPECT_TRUE(back[2].lost);
}

TEST_F(TrackLogTest, EmptyLogsAreValid) {
  write_all(path("t.csv"), {});
  EXPECT_TRUE(eval::read_track_csv(path("t.csv")).empty());
  write_all(path("t.json"), {});
  EXPECT_EQ(nlohmann::json::parse(read_text(path("t.json"))), nlohmann::json::array());
}

// The array is closed after every record, so a run killed between two frames leaves valid JSON.
TEST_F(TrackLogTest, JsonIsValidAfterEveryRecord) {
  const std::vector<TrackRecord> records = sample_records();
  TrackLogWriter log(path("t.json"));
  for (std::size_t i = 0; i < records.size(); ++i) {
    log.write(records[i]);
    const nlohmann::json doc = nlohmann::json::parse(read_text(path("t.json")));
    ASSERT_TRUE(doc.is_array());
    EXPECT_EQ(doc.size(), i + 1);
  }
  log.close();
  const std::string text = read_text(path("t.json"));
  EXPECT_EQ(text.back(), '\n');
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 5) << text;  // [, 3 records, ]

  const nlohmann::json doc = nlohmann::json::parse(text);
  ASSERT_EQ(doc.size(), 3u);
  std::vector<std::string> keys;
  for (const auto& item : doc[1].items())
    keys.push_back(item.key());
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, (std::vector<std::string>{"frame", "h", "id", "lost", "mode", "ms", "vx", "vy",
                                            "w", "x", "y"}));
  EXPECT_EQ(doc[1]["frame"], 2);
  EXPECT_TRUE(doc[1]["frame"].is_number_integer());
  EXPECT_EQ(doc[1]["mode"], "local");
  EXPECT_EQ(doc[1]["lost"], false);
  EXPECT_EQ(doc[2]["lost"], true);
  // The same rounding as the CSV.
  EXPECT_DOUBLE_EQ(doc[1]["x"].get<double>(), 71.26);
  EXPECT_DOUBLE_EQ(doc[1]["vx"].get<double>(), 1.256);
  EXPECT_DOUBLE_EQ(doc[1]["vy"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(doc[1]["ms"].get<double>(), 0.432);
}

TEST_F(TrackLogTest, DestructorClosesAndEveryRecordIsFlushedAtOnce) {
  {
    TrackLogWriter csv(path("t.csv"));
    TrackLogWriter json(path("t.json"));
    csv.write(sample_records()[0]);
    json.write(sample_records()[0]);
    // Readable before close: a crash now would lose nothing.
    EXPECT_EQ(eval::read_track_csv(path("t.csv")).size(), 1u);
    EXPECT_EQ(nlohmann::json::parse(read_text(path("t.json"))).size(), 1u);
    csv.write(sample_records()[1]);
  }
  EXPECT_EQ(eval::read_track_csv(path("t.csv")).size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(read_text(path("t.json"))).size(), 1u);
}

TEST_F(TrackLogTest, FormatComesFromTheExtension) {
  write_all(path("upper.JSON"), sample_records());
  EXPECT_EQ(nlohmann::json::parse(read_text(path("upper.JSON"))).size(), 3u);
  for (const char* name : {"t.txt", "t", "t.csv.gz", "t.jsonl"}) {
    const std::string message = test::error_message([&] { TrackLogWriter log(path(name)); });
    EXPECT_NE(message.find(path(name)), std::string::npos) << message;
    EXPECT_FALSE(std::filesystem::exists(path(name))) << name;
  }
  const std::string missing = path("no/such/dir/t.csv");
  const std::string message = test::error_message([&] { TrackLogWriter log(missing); });
  EXPECT_NE(message.find(missing), std::string::npos) << message;
}

TEST_F(TrackLogTest, RejectsRecordsTheReaderCouldNotTakeBack) {
  TrackLogWriter log(path("t.csv"));
  TrackRecord nan_x;
  nan_x.frame = 4;
  nan_x.box.x = std::numeric_limits<float>::quiet_NaN();
  TrackRecord frame_zero;
  frame_zero.frame = 0;
  TrackRecord negative;
  negative.box.width = -1;
  TrackRecord infinite_ms;
  infinite_ms.ms = std::numeric_limits<double>::infinity();
  for (const auto& [record, expected] :
       {std::pair{nan_x, "frame 4: x is nan"}, std::pair{frame_zero, "frame 0"},
        std::pair{negative, "negative box size"}, std::pair{infinite_ms, "ms is inf"}}) {
    const std::string message = test::error_message([&] { log.write(record); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_NE(message.find(path("t.csv")), std::string::npos) << message;
  }
  log.close();
  EXPECT_NE(test::error_message([&] { log.write(TrackRecord{}); }).find("closed"),
            std::string::npos);
  EXPECT_TRUE(eval::read_track_csv(path("t.csv")).empty());
}

TEST_F(TrackLogTest, ParseTrackCsvReadsTextAndNamesItInErrors) {
  write_all(path("t.csv"), sample_records());
  const std::vector<TrackRecord> records = eval::parse_track_csv(read_text(path("t.csv")), "mem");
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2].frame, 3);
  EXPECT_TRUE(records[2].lost);
  const std::string message =
      test::error_message([] { eval::parse_track_csv("frame,x\n", "mem.csv"); });
  EXPECT_NE(message.find("mem.csv:1: header"), std::string::npos) << message;
  EXPECT_NE(test::error_message([] { eval::parse_track_csv("", "e"); }).find("e:1: empty file"),
            std::string::npos);
}

}  // namespace
