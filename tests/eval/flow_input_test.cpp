#include "eval/flow_input.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>

#include "eval/score_text.hpp"
#include "eval/track_log.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;

TEST(FlowInput, APairOrASyntheticSceneNeverBoth) {
  const cv::Size size(64, 48);
  const auto usage = [&](const std::string& a, const std::string& b, const std::string& gt,
                         const std::string& scene) {
    try {
      eval::flow_input(a, b, gt, scene, size);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("no UsageError");
  };
  EXPECT_EQ(usage("a.png", "", "", ""), "flow needs two images A B, or --synthetic [scene]");
  EXPECT_EQ(usage("a.png", "", "", "zoom"), "give either two images A B or --synthetic, not both");
  EXPECT_EQ(usage("", "", "gt.flo", "zoom"),
            "--gt: a --synthetic scene brings its own ground truth");
  const eval::FlowInput in = eval::flow_input("", "", "", "zoom", size);
  EXPECT_EQ(in.frame0.size(), size);
  EXPECT_EQ(in.truth.size(), size);
  EXPECT_NE(in.source.find("zoom"), std::string::npos) << in.source;
  // A missing file is a run-time error naming it, not a usage error.
  EXPECT_NE(test::error_message([] {
              eval::flow_input("missing.png", "b.png", "", "", {8, 8});
            }).find("missing.png"),
            std::string::npos);
}

class ScoreText : public test::TempDirTest {};

TEST_F(ScoreText, OtbTableAndJsonOfTheSameFiles) {
  std::ofstream(path("gt.txt")) << "10,10,40,30\n12,11,40,30\n";
  std::string log = std::string(eval::kTrackCsvHeader) + "\n";
  for (const auto& [frame, box] :
       {std::pair{1, cv::Rect2f(10, 10, 40, 30)}, std::pair{2, cv::Rect2f(32, 11, 40, 30)}}) {
    eval::TrackRecord r;
    r.frame = frame;
    r.box = box;
    log += eval::track_csv_row(r);
  }
  std::ofstream(path("track.csv")) << log;
  const std::string table = eval::score_text(path("track.csv"), path("gt.txt"), false, "table");
  const std::string json = eval::score_text(path("track.csv"), path("gt.txt"), false, "json");
  EXPECT_NE(table.find("AUC"), std::string::npos) << table;
  const auto doc = nlohmann::json::parse(json);
  EXPECT_EQ(doc.at("frames").get<int>(), 2);
  EXPECT_GT(doc.at("auc").get<double>(), 0.4);
  EXPECT_LT(doc.at("auc").get<double>(), 0.8);  // the second box is off by 20 px
  EXPECT_DOUBLE_EQ(doc.at("precision20").get<double>(), 1.0);
  EXPECT_NE(test::error_message([&] {
              eval::score_text(path("none.csv"), path("gt.txt"), false, "table");
            }).find("none.csv"),
            std::string::npos);
}

}  // namespace
