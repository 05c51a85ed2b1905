#include "stages/atomic_write.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;
using test::read_text;
namespace fs = std::filesystem;

class AtomicWriteTest : public test::TempDirTest {
 protected:
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_))
      names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
};

TEST(AtomicWritePartialPath, HiddenInSameDirectoryKeepingExtension) {
  EXPECT_EQ(stages::partial_path("dir/name.png"), "dir/.name.partial.png");
  EXPECT_EQ(stages::partial_path("a/b/run.summary.json"), "a/b/.run.summary.partial.json");
  EXPECT_EQ(stages::partial_path("name"), ".name.partial");
}

TEST_F(AtomicWriteTest, WritesThePartialThenRenamesIt) {
  const std::string target = path("out.txt");
  std::string seen;
  stages::write_atomically(target, "", [&](const std::string& partial) {
    seen = partial;
    EXPECT_FALSE(fs::exists(target)) << "the final name must not exist while writing";
    std::ofstream(partial) << "hello";
    return true;
  });
  EXPECT_EQ(seen, path(".out.partial.txt"));
  EXPECT_EQ(read_text(target), "hello");
  EXPECT_EQ(files(), std::vector<std::string>{"out.txt"});
}

TEST_F(AtomicWriteTest, TextReplacesAnExistingFile) {
  const std::string target = path("summary.json");
  stages::write_text_atomically(target, "old, longer content");
  stages::write_text_atomically(target, "{}\n");
  EXPECT_EQ(read_text(target), "{}\n");
  EXPECT_EQ(files(), std::vector<std::string>{"summary.json"});
}

TEST_F(AtomicWriteTest, FailedWriteKeepsTheOldFileAndRemovesThePartial) {
  const std::string target = path("log.txt");
  stages::write_text_atomically(target, "old");
  const std::string message = test::error_message([&] {
    stages::write_atomically(target, "thing ", [](const std::string& partial) {
      std::ofstream(partial) << "half";
      return false;
    });
  });
  EXPECT_EQ(message, "cannot write thing '" + target + "'");
  EXPECT_EQ(read_text(target), "old");
  EXPECT_EQ(files(), std::vector<std::string>{"log.txt"});
}

TEST_F(AtomicWriteTest, CvExceptionBecomesError) {
  const std::string target = path("x.png");
  const std::string message = test::error_message([&] {
    stages::write_atomically(target, "image ", [](const std::string& partial) -> bool {
      std::ofstream(partial) << "half";
      CV_Error(cv::Error::StsError, "encoder failed");
    });
  });
  EXPECT_EQ(message, "cannot write image '" + target + "'");
  EXPECT_TRUE(files().empty());
}

TEST_F(AtomicWriteTest, OtherExceptionsPropagateWithoutLeavingThePartial) {
  EXPECT_THROW(stages::write_atomically(path("x.txt"), "",
                                        [](const std::string& partial) -> bool {
                                          std::ofstream(partial) << "half";
                                          throw std::logic_error("bug");
                                        }),
               std::logic_error);
  EXPECT_TRUE(files().empty());
}

TEST_F(AtomicWriteTest, MissingDirectoryThrowsNamingThePath) {
  const std::string target = path("missing/out.txt");
  EXPECT_EQ(test::error_message([&] { stages::write_text_atomically(target, "x"); }),
            "cannot write '" + target + "'");
}

TEST_F(AtomicWriteTest, ImageRoundTripsInTheFormatOfTheExtension) {
  cv::Mat image(12, 17, CV_8UC3);
  cv::randu(image, 0, 256);
  stages::write_image_atomically(path("frame.png"), image);
  const cv::Mat back = cv::imread(path("frame.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  EXPECT_EQ(files(), std::vector<std::string>{"frame.png"});
}

TEST_F(AtomicWriteTest, ImageWithUnknownExtensionThrows) {
  const std::string target = path("frame.nosuchformat");
  EXPECT_EQ(
      test::error_message([&] { stages::write_image_atomically(target, cv::Mat(4, 4, CV_8UC1)); }),
      "cannot write image '" + target + "'");
  EXPECT_TRUE(files().empty());
}

}  // namespace
