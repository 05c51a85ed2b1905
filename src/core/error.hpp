// roiflow::Error — the one exception type of the library.
//
//   if (patch < 3) throw roiflow::Error(fmt("patch must be in 3..31, got {}", patch));
//
// Every bad argument (wrong size, absurd parameter, corrupt file) throws this with a message
// that names the offending value, so the CLI can print it on one line and exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace roiflow {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace roiflow
