// Replays the fuzzers' findings and seeds through the normal build's parsers.
//
// tests/fuzz_regressions/<target>/ holds every input that once crashed a fuzz target (see
// scripts/fuzz.sh); each must now be refused with a clean roiflow::Error or parsed into values
// that keep the parser's promises, exactly as the fuzz target checks them (fuzz/fuzz_checks.hpp).
// The seed corpus (fuzz/seed_corpus.hpp) must parse.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "../../fuzz/fuzz_checks.hpp"
#include "../../fuzz/seed_corpus.hpp"
#include "test_util.hpp"

namespace roiflow::fuzz {
namespace {

namespace fs = std::filesystem;

const std::map<std::string, std::function<void(std::string_view)>>& checks() {
  static const std::map<std::string, std::function<void(std::string_view)>> all = {
      {"flo", check_flo},
      {"ground_truth", check_ground_truth},
      {"track_csv", check_track_csv},
      {"kitti_flow", check_kitti_flow},
  };
  return all;
}

fs::path regressions_dir() {
  return fs::path(__FILE__).parent_path().parent_path() / "fuzz_regressions";
}

class FuzzSeedCorpusTest : public test::TempDirTest {};

TEST_F(FuzzSeedCorpusTest, EverySeedParses) {
  const auto corpus = seed_corpus(dir_);
  for (const char* target : {"flo", "ground_truth", "track_csv", "cli_options", "kitti_flow"}) {
    ASSERT_TRUE(corpus.contains(target)) << target;
    EXPECT_FALSE(corpus.at(target).empty()) << target;
  }
  for (const std::string& bytes : corpus.at("flo")) {
    EXPECT_NO_THROW(eval::parse_flo(bytes, "seed.flo"));
    EXPECT_NO_THROW(check_flo(bytes));
  }
  for (const std::string& bytes : corpus.at("kitti_flow")) {
    const std::vector<uchar> data(bytes.begin(), bytes.end());
    EXPECT_NO_THROW(eval::decode_kitti_flow(cv::imdecode(data, cv::IMREAD_UNCHANGED)));
    EXPECT_NO_THROW(check_kitti_flow(bytes));
  }
  for (const std::string& text : corpus.at("ground_truth")) {
    EXPECT_NO_THROW(eval::parse_ground_truth(text, "seed.txt")) << text;
    EXPECT_NO_THROW(check_ground_truth(text)) << text;
  }
  for (const std::string& text : corpus.at("track_csv")) {
    EXPECT_EQ(eval::parse_track_csv(text, "seed.csv").size(), 3u) << text;
    EXPECT_NO_THROW(check_track_csv(text)) << text;
  }
}

TEST(FuzzRegressionTest, EverySavedCrashInputIsHandled) {
  const fs::path root = regressions_dir();
  ASSERT_TRUE(fs::is_directory(root)) << root;
  int replayed = 0;
  for (const fs::directory_entry& target : fs::directory_iterator(root)) {
    if (!target.is_directory()) continue;
    const std::string name = target.path().filename().string();
    const auto check = checks().find(name);
    // cli_options needs apps/cli_common.cpp, which the suite does not link: its inputs are
    // replayed by the CliTest cases that reproduce them.
    if (name == "cli_options") continue;
    ASSERT_NE(check, checks().end()) << "no replay for fuzz target '" << name << "'";
    for (const fs::directory_entry& input : fs::directory_iterator(target.path())) {
      if (!input.is_regular_file()) continue;
      const std::string bytes = file_bytes(input.path());
      EXPECT_NO_THROW(check->second(bytes)) << input.path();
      ++replayed;
    }
  }
  std::printf("replayed %d saved fuzz inputs\n", replayed);
}

}  // namespace
}  // namespace roiflow::fuzz
