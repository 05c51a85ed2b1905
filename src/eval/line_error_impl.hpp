#pragma once
// Internal to the eval part: the error of one line of a text file, "PATH:LINE: what", as the
// readers of ground truth, track logs and MOTChallenge files report it.

#include <string>

#include "core/error.hpp"

namespace roiflow::eval::detail {

class LineError {
 public:
  LineError(const std::string& path, long long line) : prefix_(path + ":" + std::to_string(line)) {}
  [[noreturn]] void fail(const std::string& what) const { throw Error(prefix_ + ": " + what); }

 private:
  std::string prefix_;
};

}  // namespace roiflow::eval::detail
