// `roiflow track` on every moving object (no --init): the log with an id column, the
// MOTChallenge file, the summary's counts; known targets by --init twice and --init-file;
// motion-check; bad options and files.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "eval/mot.hpp"
#include "eval/track_log.hpp"
#include "test_util.hpp"

namespace roiflow {
namespace {

using test::CliResult;

class TrackObjectsCliTest : public test::TempDirTest {
 protected:
  CliResult run(const std::vector<std::string>& args) const {
    return test::run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }
};

constexpr const char* kScene = "synthetic:150:320x240:4";

TEST_F(TrackObjectsCliTest, FollowsEveryVehicleOfTheTrafficScene) {
  const CliResult r =
      run({"track", kScene, "--threads", "2", "--no-progress", "--mot", path("mot.txt"), "--log",
           path("log.csv"), "--summary", path("s.json"), "--out", path("frames")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("objects born"), std::string::npos) << r.out;
  std::ifstream header_file(path("log.csv"));
  std::string header;
  std::getline(header_file, header);
  EXPECT_EQ(header, "frame,id,x,y,w,h,vx,vy,mode,lost,ms");
  const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("log.csv"));
  std::set<long long> ids;
  for (const eval::TrackRecord& rec : log)
    ids.insert(rec.id);
  EXPECT_GE(ids.size(), 3u);
  const std::vector<eval::MotBox> mot = eval::read_mot(path("mot.txt"), "mot");
  EXPECT_GT(mot.size(), 150u);
  for (const eval::MotBox& b : mot) {
    EXPECT_GE(b.box.width, 8);
    EXPECT_GE(b.box.height, 8);
  }
  std::ifstream summary_file(path("s.json"));
  const nlohmann::json s = nlohmann::json::parse(summary_file);
  EXPECT_EQ(s.at("frames").get<long long>(), 150);
  EXPECT_GE(s.at("objects_born").get<long long>(), 3);
  EXPECT_GE(s.at("global_activations").get<long long>(), 1);
  EXPECT_TRUE(std::filesystem::exists(path("frames/000150.png")));
  // Scored against the scene's exact boxes.
  const CliResult score = run({"score", "--mot", path("mot.txt"), kScene, "--format", "json"});
  ASSERT_EQ(score.exit_code, 0) << score.err;
  const nlohmann::json j = nlohmann::json::parse(score.out);
  // A smoke floor (150 frames of 4 small vehicles: 0.40 measured; docs/TRACKING.md has the
  // scene sizes scored).
  EXPECT_GT(j.at("mota").get<double>(), 0.35) << score.out;
  EXPECT_GT(j.at("idf1").get<double>(), 0.4) << score.out;
  // And the found boxes move with moving pixels.
  const CliResult check = run({"motion-check", kScene, path("log.csv"), "--format", "json"});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST_F(TrackObjectsCliTest, KnownTargetsKeepTheirIds) {
  std::ofstream(path("targets.txt")) << "# id,x,y,w,h\n4,40,40,30,20\n9,200,150,30,20\n";
  const CliResult r = run({"track", kScene, "--no-progress", "--init-file", path("targets.txt"),
                           "--log", path("log.csv"), "--max-frames", "20"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::set<long long> ids;
  for (const eval::TrackRecord& rec : eval::read_track_csv(path("log.csv")))
    ids.insert(rec.id);
  EXPECT_EQ(ids, (std::set<long long>{4, 9}));
  const CliResult two = run({"track", kScene, "--no-progress", "--init", "40,40,30,20", "--init",
                             "200,150,30,20", "--log", path("log2.csv"), "--max-frames", "10"});
  ASSERT_EQ(two.exit_code, 0) << two.err;
  ids.clear();
  for (const eval::TrackRecord& rec : eval::read_track_csv(path("log2.csv")))
    ids.insert(rec.id);
  EXPECT_EQ(ids, (std::set<long long>{1, 2}));
}

TEST_F(TrackObjectsCliTest, BadTargetsAndOptionsFailWithOneLine) {
  std::ofstream(path("bad.txt")) << "1,10,10,20,20\n2,10,nan,20,20\n";
  std::ofstream(path("outside.txt")) << "1,5000,5000,20,20\n";
  const struct {
    std::vector<std::string> args;
    int code;
    std::string expected;
  } cases[] = {
      {{"track", kScene, "--init-file", path("missing.txt")}, 2, "missing.txt"},
      {{"track", kScene, "--init-file", path("bad.txt")}, 2, "bad.txt:2: y 'nan'"},
      {{"track", kScene, "--init-file", path("outside.txt")}, 2, "outside"},
      {{"track", kScene, "--init", "1,2,3,4", "--init", "1,2,3"}, 2, "--init"},
      {{"track", kScene, "--single", "--mot", path("m.txt")}, 2, "--mot"},
      {{"track", kScene, "--mot", path("no/such/dir/m.txt")}, 1, "no/such/dir"},
      {{"motion-check", kScene, path("missing.csv")}, 1, "missing.csv"},
  };
  for (const auto& c : cases) {
    const CliResult r = run(c.args);
    test::expect_one_error_line(r, c.code, c.expected);
  }
}

}  // namespace
}  // namespace roiflow
