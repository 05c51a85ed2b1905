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

// A request that makes no sense before any input is read (conflicting options, a parameter out
// of range, a box outside the frame): the CLI reports it like a command-line error (exit code 2).
class UsageError : public Error {
 public:
  using Error::Error;
};

}  // namespace roiflow
