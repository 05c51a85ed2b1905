// Helpers shared by the test files.
//
//   EXPECT_NE(error_message([&] { read_flo(path); }).find(path), std::string::npos);
//   class MyTest : public roiflow::test::TempDirTest {};   // path("out.flo") is in a fresh dir
//   CliResult r = run_cli({"eval", dir}, path("stdout.txt"), path("stderr.txt"));
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

extern "C" char** environ;

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

// [begin, end) cut into chunks of `grain` (at least 1) rows, in order: what an Executor's
// for_range hands its body.
inline std::vector<std::pair<int, int>> chunks_of(int begin, int end, int grain) {
  const int step = std::max(1, grain);
  std::vector<std::pair<int, int>> chunks;
  for (int b = begin; b < end; b += step)
    chunks.emplace_back(b, std::min(end, b + step));
  return chunks;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// The largest absolute difference of two images of one size and type (a failed expectation, and
// the largest double, when they differ in either).
inline double max_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.type(), b.type());
  if (a.size() != b.size() || a.type() != b.type()) return std::numeric_limits<double>::max();
  return cv::norm(a, b, cv::NORM_INF);
}

inline std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::istringstream in(text);
  for (std::string part; std::getline(in, part, separator);)
    parts.push_back(part);
  return parts;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  return split(text, '\n');
}

struct CliResult {
  int exit_code = -1;  // -1 when the process did not exit normally
  std::string out;
  std::string err;
};

// A failed run: exit code `exit_code`, nothing on stdout, one line on stderr, that line
// "roiflow: error: ..." holding `expected`.
inline void expect_one_error_line(const CliResult& r, int exit_code, const std::string& expected) {
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("roiflow: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

#ifdef ROIFLOW_CLI_PATH
// Starts the roiflow CLI with `args` (no shell), stdout and stderr going to the two files.
// Returns its pid, or -1 with posix_spawn's error in `*error`.
inline pid_t spawn_cli(const std::vector<std::string>& args, const std::string& out_path,
                       const std::string& err_path, int* error = nullptr) {
  std::vector<std::string> argv_text = {ROIFLOW_CLI_PATH};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : argv_text)
    argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (error != nullptr) *error = rc;
  return rc == 0 ? pid : -1;
}

// Runs the roiflow CLI with `args` through the shell (each argument quoted), its stdout and
// stderr going to two files that are read back and removed.
inline CliResult run_cli(const std::vector<std::string>& args, const std::string& out_path,
                         const std::string& err_path) {
  const auto append_quoted = [](std::string& command, const std::string& arg) {
    command += " '";
    for (char c : arg)
      command += c == '\'' ? std::string("'\\''") : std::string(1, c);
    command += '\'';
  };
  std::string command;
  append_quoted(command, ROIFLOW_CLI_PATH);
  for (const std::string& arg : args)
    append_quoted(command, arg);
  command += " >";
  append_quoted(command, out_path);
  command += " 2>";
  append_quoted(command, err_path);
  const int status = std::system(command.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_text(out_path);
  result.err = read_text(err_path);
  std::filesystem::remove(out_path);
  std::filesystem::remove(err_path);
  return result;
}
#endif

}  // namespace roiflow::test
