// roiflow track --compare, end to end: both modes run one after the other in the process.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "eval/track_log.hpp"
#include "eval/tracking_scene.hpp"
#include "scene_video.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;
using test::CliResult;
using test::lines_of;
using test::read_text;
using test::run_cli;

class CompareCliTest : public test::TempDirTest {
 protected:
  // The demo's scene, 160x120, 24 frames, as MJPG .avi.
  void SetUp() override {
    TempDirTest::SetUp();
    scene_ = test::write_scene_video(path("scene.avi"), 24);
  }

  std::string init_box() const { return test::box_text(scene_->box(0)); }

  CliResult run(const std::vector<std::string>& args) const {
    return run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }

  std::unique_ptr<eval::TrackingScene> scene_;
};

TEST_F(CompareCliTest, RunsBothModesAndWritesTableCsvJsonAndPlots) {
  const std::string dir = path("cmp");
  const CliResult r =
      run({"track", path("scene.avi"), "--init", init_box(), "--compare", "--compare-out", dir,
           "--compare-patches", "6,10", "--threads", "2", "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  // The table: a header, then one row per mode.
  const std::vector<std::string> out = lines_of(r.out);
  ASSERT_GE(out.size(), 5u) << r.out;
  EXPECT_NE(out[1].find("tracker fps"), std::string::npos) << r.out;
  EXPECT_EQ(out[2].rfind("local ", 0), 0u) << r.out;
  EXPECT_EQ(out[3].rfind("global ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("x faster than global"), std::string::npos) << r.out;

  const auto doc = nlohmann::json::parse(read_text(dir + "/compare.json"));
  const auto& local = doc.at("local");
  const auto& global = doc.at("global");
  EXPECT_EQ(local.at("frames").get<double>(), 24);
  EXPECT_EQ(global.at("frames").get<double>(), 24);
  EXPECT_EQ(global.at("global_activations").get<double>(), 24);
  EXPECT_LT(local.at("global_activations").get<double>(), global.at("global_activations"));
  for (const auto* mode : {&local, &global}) {
    EXPECT_GT(mode->at("tracker_fps").get<double>(), 0);
    EXPECT_GT(mode->at("peak_rss_mb").get<double>(), 1);
    EXPECT_LE(mode->at("ms_median").get<double>(), mode->at("ms_p95").get<double>());
  }
  // A 160x120 frame every frame costs more than a 50x50 region.
  EXPECT_GT(global.at("ms_median").get<double>(), local.at("ms_median").get<double>());
  ASSERT_EQ(doc.at("patches").size(), 2u);
  EXPECT_EQ(doc.at("patches")[0].at("patch").get<int>(), 6);

  // The per-mode logs the medians came from.
  EXPECT_EQ(eval::read_track_csv(dir + "/local.csv").size(), 24u);
  EXPECT_EQ(eval::read_track_csv(dir + "/global.csv").size(), 24u);

  const std::vector<std::string> csv = lines_of(read_text(dir + "/compare.csv"));
  ASSERT_EQ(csv.size(), 7u);  // header, 2 main rows, 2 x 2 patch rows
  EXPECT_EQ(csv[0],
            "patch,mode,frames,fps,tracker_fps,ms_median,ms_p95,ms_mean,global_activations,"
            "peak_rss_mb");
  EXPECT_EQ(csv[1].rfind("10,local,24,", 0), 0u) << csv[1];
  EXPECT_EQ(csv[4].rfind("6,global,24,", 0), 0u) << csv[4];
  for (const char* svg : {"/ms_per_frame.svg", "/patches.svg"}) {
    const std::string text = read_text(dir + svg);
    EXPECT_NE(text.find("</svg>"), std::string::npos) << svg;
    EXPECT_NE(text.find(">global"), std::string::npos) << svg;
  }
  EXPECT_NE(read_text(dir + "/patches.svg").find("patch size (px)"), std::string::npos);
  // Nothing else in the folder: the other patch sizes' runs keep their logs in memory.
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.insert(entry.path().filename().string());
  EXPECT_EQ(names,
            (std::set<std::string>{"compare.csv", "compare.json", "global.csv", "global.json",
                                   "local.csv", "local.json", "ms_per_frame.svg", "patches.svg"}));
}

TEST_F(CompareCliTest, BadCommandLinesFailWithOneLine) {
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;
  };
  const std::string video = path("scene.avi");
  const std::vector<Case> cases = {
      {{"track", video, "--compare", "--mode", "global"}, 2, "--mode"},
      {{"track", video, "--compare", "--log", path("t.csv")}, 2, "--log"},
      {{"track", video, "--compare-patches", "6,10"}, 2, "--compare"},
      {{"track", video, "--compare", "--compare-patches", "6,40"}, 2, "--compare-patches"},
      {{"track", "0", "--compare", "--compare-out", path("cmp")}, 2, "camera"},
      {{"track", path("none.avi"), "--compare", "--compare-out", path("cmp")}, 1, "none.avi"},
      {{"track", video, "--compare", "--init", "900,900,10,10", "--compare-out", path("cmp")},
       2,
       "outside"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    test::expect_one_error_line(run(c.args), c.exit_code, c.expected);
    EXPECT_FALSE(fs::exists(path("cmp")));
  }
}

TEST_F(CompareCliTest, AFailingRunFailsTheComparisonWithItsMessage) {
  // The video opens fine; the first run stops half way through it.
  const std::string whole = read_text(path("scene.avi"));
  std::ofstream(path("cut.avi"), std::ios::binary) << whole.substr(0, whole.size() / 2);
  const CliResult r =
      run({"track", path("cut.avi"), "--compare", "--compare-out", path("cmp"), "--no-progress"});
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("roiflow: error: --compare: the local run (patch 10) failed: input stopped "
                       "at frame"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(path("cmp/compare.csv")));

  std::ofstream(path("file")) << "x";
  const CliResult f = run(
      {"track", path("scene.avi"), "--compare", "--compare-out", path("file"), "--no-progress"});
  EXPECT_EQ(f.exit_code, 1);
  EXPECT_NE(f.err.find("not a directory"), std::string::npos) << f.err;
}

}  // namespace
