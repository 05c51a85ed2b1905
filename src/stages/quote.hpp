// A value quoted for an error message, cut to 40 characters: a binary file read as text must
// not produce a screenful.
//
//   throw Error(path + ":" + std::to_string(line) + ": bad number " + quoted_excerpt(field));
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace roiflow::stages {

inline std::string quoted_excerpt(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string shown(1, '\'');
  shown.append(text.substr(0, kMax));
  shown.append(text.size() > kMax ? "...'" : "'");
  return shown;
}

}  // namespace roiflow::stages
