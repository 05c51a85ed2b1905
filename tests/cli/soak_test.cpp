// A short soak through the CLI: `roiflow track synthetic:N` runs the whole pipeline (source,
// decode node, pyramid pool, tracker, sinks) over a generated stream; no frame may be lost or
// reordered. scripts/soak.sh runs the long version (up to 100 000 frames) and checks that peak
// memory stays flat.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/track_log.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;

class SoakTest : public test::TempDirTest {};

TEST_F(SoakTest, TrackOverASyntheticStreamKeepsEveryFrameInOrder) {
  constexpr long long kFrames = 1500;
  const std::string command =
      std::string("'") + ROIFLOW_CLI_PATH + "' track synthetic:" + std::to_string(kFrames) +
      ":160x120 --single --threads 2 --no-progress" + " --log '" + path("log.csv") +
      "' --summary '" + path("summary.json") + "' >'" + path("out.txt") + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream out_file(path("out.txt"));
  const std::string out{std::istreambuf_iterator<char>(out_file), {}};
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;

  // Exactly frames 1..N: none lost, none repeated, none out of order.
  const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("log.csv"));
  ASSERT_EQ(static_cast<long long>(log.size()), kFrames);
  for (std::size_t i = 0; i < log.size(); ++i)
    ASSERT_EQ(log[i].frame, static_cast<long long>(i) + 1);

  std::ifstream summary_file(path("summary.json"));
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary.at("frames").get<long long>(), kFrames);
  EXPECT_EQ(summary.at("status").get<std::string>(), "end of stream");
  EXPECT_GT(summary.at("peak_rss_mb").get<double>(), 0.0);
  // The frames in flight stay bounded whatever the length (2 x threads + 2 by default).
  EXPECT_LE(summary.at("max_in_flight").get<long long>(), 6);
  // The scene's vehicle is found and followed: most frames have a target.
  long long lost = 0;
  for (const eval::TrackRecord& r : log)
    lost += r.lost ? 1 : 0;
  EXPECT_LT(lost, kFrames / 10);
}

}  // namespace
