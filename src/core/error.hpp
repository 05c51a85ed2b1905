// The library's exceptions. roiflow::Error is thrown for every bad argument, file or value, with
// a message that names the offending value, so a command line can print it on one line.
// roiflow::UsageError is the kind of Error that a request makes before any input is read (a
// parameter out of range, conflicting options): the CLI exits with code 2 for it, 1 otherwise.
//
//   const int patch = 40;
//   try {
//     if (patch > 31) throw roiflow::UsageError("patch must be in 3..31, got 40");
//   } catch (const roiflow::Error& e) {
//     std::cerr << e.what() << "\n";
//   }
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
