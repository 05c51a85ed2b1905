// Line-oriented text input shared by the track-log and ground-truth parsers: the whole file (an
// error names it and what it is), and its lines without '\n' or a Windows '\r'.
//
//   const std::string text = "x\r\ny\n";  // or roiflow::read_text_file(path, "ground truth")
//   roiflow::for_each_line(text, [](long long number, std::string_view line) {
//     std::cout << number << ": " << line << "\n";
//   });
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace roiflow {

// Calls f(number, line) for every line of `text` (numbers from 1), without its '\n' and a
// trailing '\r' (files written on Windows). A final line without '\n' counts; an empty text has
// no line. Returns the number of lines.
template <class F>
long long for_each_line(std::string_view text, F&& f) {
  long long number = 0;
  for (std::size_t start = 0; start < text.size();) {
    ++number;
    const std::size_t newline = text.find('\n', start);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    std::string_view line = text.substr(start, end - start);
    start = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    f(number, line);
  }
  return number;
}

// The whole file; `what` names it in the error ("cannot read track log 'x.csv': no such file").
inline std::string read_text_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error("cannot read " + what + " '" + path + "': no such file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open " + what + " '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad() || text.bad()) throw Error("cannot read " + what + " '" + path + "'");
  return text.str();
}

}  // namespace roiflow
