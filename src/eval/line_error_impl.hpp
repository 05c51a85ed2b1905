#pragma once
// Internal to the eval part: the error of one line of a text file, "PATH:LINE: what", as the
// readers of ground truth, track logs and MOTChallenge files report it.

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::eval::detail {

class LineError {
 public:
  LineError(const std::string& path, long long line) : prefix_(path + ":" + std::to_string(line)) {}
  [[noreturn]] void fail(const std::string& what) const { throw Error(prefix_ + ": " + what); }
  // The finite number `field` holds, whole; otherwise fail() naming the field `name`.
  double number(std::string_view field, const char* name) const {
    double value = 0;
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (ec != std::errc() || end != field.data() + field.size() || !std::isfinite(value)) {
      fail(std::string(name) + " " + quoted_excerpt(field) + " is not a finite number");
    }
    return value;
  }

 private:
  std::string prefix_;
};

}  // namespace roiflow::eval::detail
