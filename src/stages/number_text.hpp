// A number as error messages show it: the shortest stream form ("0.5", "1e-06", "nan"), so that
// the value the user gave reads back as they wrote it.
//
//   throw Error("roi must be in 8..4096, got " + number_text(roi));
#pragma once

#include <sstream>
#include <string>

namespace roiflow::stages {

inline std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace roiflow::stages
