#include "pipeline/mot_demo.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "eval/mot.hpp"
#include "eval/traffic_scene.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;
namespace fs = std::filesystem;

class MotDemoTest : public test::TempDirTest {};

TEST_F(MotDemoTest, WritesFilesWhoseScoreTheSummaryHolds) {
  pipeline::MotDemoOptions o;
  o.dir = path("demo");
  o.objects = 3;
  o.frames = 40;
  o.size = {320, 240};
  o.threads = 2;
  o.video = false;
  const pipeline::MotDemoResult r = pipeline::run_mot_demo(o);
  ASSERT_FALSE(r.cancelled);
  for (const std::string& f : {r.mot, r.ground_truth, r.log, r.summary_path})
    EXPECT_TRUE(fs::is_regular_file(f)) << f;
  EXPECT_FALSE(fs::exists(path("demo/demo.mp4")));
  // The ground truth file is the scene's, and the figures are those of the two files.
  eval::TrafficSceneParams p;
  p.size = {320, 240};
  p.frames = 40;
  p.objects = 3;
  EXPECT_EQ(test::read_text(r.ground_truth),
            eval::format_mot(eval::TrafficScene(p).ground_truth()));
  const eval::MotScore s = eval::score_mot(eval::read_mot(r.mot, "tracker output"),
                                           eval::read_mot(r.ground_truth, "ground truth"));
  const nlohmann::json summary = nlohmann::json::parse(test::read_text(r.summary_path));
  EXPECT_DOUBLE_EQ(summary.at("mota").get<double>(), s.mota);
  EXPECT_DOUBLE_EQ(summary.at("idf1").get<double>(), s.idf1);
  EXPECT_EQ(summary.at("fn").get<long long>(), s.fn);
  EXPECT_EQ(summary.at("frames").get<long long>(), 40);
  EXPECT_DOUBLE_EQ(r.score.mota, s.mota);
  EXPECT_GT(s.gt_boxes, 40);  // three vehicles, most of them inside most of the time
}

TEST_F(MotDemoTest, BadOptionsThrowBeforeWriting) {
  pipeline::MotDemoOptions o;
  o.dir = path("no/such/parent/demo");
  o.frames = 5;
  EXPECT_NE(test::error_message([&] { pipeline::run_mot_demo(o); }).find("does not exist"),
            std::string::npos);
  o.dir = path("demo");
  o.objects = 0;
  EXPECT_NE(test::error_message([&] { pipeline::run_mot_demo(o); }).find("objects"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(path("demo")));
}

}  // namespace
