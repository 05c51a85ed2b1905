#include "core/atomic_write.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
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
  EXPECT_EQ(partial_path("dir/name.png"), "dir/.name.partial.png");
  EXPECT_EQ(partial_path("a/b/run.summary.json"), "a/b/.run.summary.partial.json");
  EXPECT_EQ(partial_path("name"), ".name.partial");
}

TEST_F(AtomicWriteTest, WritesThePartialThenRenamesIt) {
  const std::string target = path("out.txt");
  std::string seen;
  write_atomically(target, "", [&](const std::string& partial) {
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
  write_text_atomically(target, "old, longer content");
  write_text_atomically(target, "{}\n");
  EXPECT_EQ(read_text(target), "{}\n");
  EXPECT_EQ(files(), std::vector<std::string>{"summary.json"});
}

TEST_F(AtomicWriteTest, FailedWriteKeepsTheOldFileAndRemovesThePartial) {
  const std::string target = path("log.txt");
  write_text_atomically(target, "old");
  const std::string message = test::error_message([&] {
    write_atomically(target, "thing ", [](const std::string& partial) {
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
    write_atomically(target, "image ", [](const std::string& partial) -> bool {
      std::ofstream(partial) << "half";
      CV_Error(cv::Error::StsError, "encoder failed");
    });
  });
  EXPECT_EQ(message, "cannot write image '" + target + "'");
  EXPECT_TRUE(files().empty());
}

TEST_F(AtomicWriteTest, OtherExceptionsPropagateWithoutLeavingThePartial) {
  EXPECT_THROW(write_atomically(path("x.txt"), "",
                                [](const std::string& partial) -> bool {
                                  std::ofstream(partial) << "half";
                                  throw std::logic_error("bug");
                                }),
               std::logic_error);
  EXPECT_TRUE(files().empty());
}

TEST_F(AtomicWriteTest, MissingDirectoryThrowsNamingThePath) {
  const std::string target = path("missing/out.txt");
  EXPECT_EQ(test::error_message([&] { write_text_atomically(target, "x"); }),
            "cannot write '" + target + "'");
}

}  // namespace
