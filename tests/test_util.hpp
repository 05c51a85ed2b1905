// Helpers shared by the test files.
//
//   EXPECT_NE(error_message([&] { read_flo(path); }).find(path), std::string::npos);
//   class MyTest : public roiflow::test::TempDirTest {};   // path("out.flo") is in a fresh dir
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <exception>
#include <filesystem>
#include <string>

#include "flow/error.hpp"

namespace roiflow::test {

// What f throws as roiflow::Error, or a text that makes the test's expectation fail.
template <class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("unexpected exception type: ") + e.what();
  }
  return "no exception";
}

// A fixture with a fresh, private directory, removed after the test.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "roiflow_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string path(const std::string& relative) const { return (dir_ / relative).string(); }

  std::filesystem::path dir_;
};

}  // namespace roiflow::test
